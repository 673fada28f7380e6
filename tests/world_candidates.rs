//! The candidate list kept between grid rebuilds, and the per-body inputs written by the drift pass, give
//! the same step as building them afresh.
//!
//! Stage 3 keeps the previous step's candidate list while the broad phase's lists and every body's dynamic
//! flag stay the same, and reads the centres and flags that the drift pass wrote
//! (`src/world/body_inputs.rs`). A run with one scratch kept over the steps must equal, bit for bit, a run
//! with a fresh scratch at every step (which rebuilds the list and the inputs every time), also when a body
//! stops being dynamic in the middle of the run without a grid rebuild (its pairs with fixed bodies leave
//! the list) and becomes dynamic again, and when the world is replaced by a clone between steps.

#[path = "support/bed.rs"]
mod bed;

use polydem::dynamics::Motion;
use polydem::dynamics::RigidBody;
use polydem::world::{step, StepScratch, World};

const STEPS: usize = 120;

/// The test bed of `tests/world_parallel.rs` with the neighbours below body 40 fixed, so that the `non_dynamic_pairs`
/// skip has pairs to leave out.
fn bed() -> bed::Bed {
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 2.0,
        ..bed::BedSpec::rocks([6, 6, 4], 4, 20261122)
    };
    let mut bed = bed::build(&spec);
    for i in [3, 4, 5, 10] {
        let fix = |b: &mut RigidBody| {
            b.motion = Motion::Fixed;
            b.velocity *= 0.0;
            b.angular_momentum *= 0.0;
        };
        bed.world.edit_body(i, fix).expect("a body");
    }
    bed
}

/// Runs the bed, switching body 40 to fixed at step 40 and back to dynamic at step 70; `fresh` gives the
/// step a new scratch every step. Returns the world and the summed candidate counts.
fn run(fresh: bool) -> (World, u64, u64) {
    let mut bed = bed();
    let mut scratch = StepScratch::default();
    let (mut candidates, mut rebuilds) = (0, 0);
    for k in 0..STEPS {
        if k == 40 {
            bed.world
                .set_body_motion(40, Motion::Fixed)
                .expect("body 40");
        }
        if k == 70 {
            bed.world
                .set_body_motion(40, Motion::Dynamic)
                .expect("body 40");
        }
        if k == 90 {
            // A clone of the world (same broad-phase generation, same store) continues the run.
            bed.world = bed.world.clone();
        }
        if fresh {
            scratch = StepScratch::default();
        }
        let r = step(&bed.params, &mut bed.world, &mut scratch).expect("step");
        candidates += r.counters.body_pairs_tested + r.counters.wall_pairs_tested;
        rebuilds += r.counters.broad_rebuilds;
    }
    (bed.world, candidates, rebuilds)
}

fn bits(w: &World) -> Vec<u64> {
    w.bodies()
        .iter()
        .flat_map(|b| {
            b.position
                .coords
                .iter()
                .chain(b.velocity.iter())
                .chain(b.orientation.coords.iter())
                .chain(b.angular_momentum.iter())
                .map(|x| x.to_bits())
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn a_kept_candidate_list_steps_as_a_rebuilt_one() {
    let (kept, kept_candidates, kept_rebuilds) = run(false);
    let (fresh, fresh_candidates, fresh_rebuilds) = run(true);
    assert!(
        kept_rebuilds < STEPS as u64 / 2,
        "the grid was rebuilt {kept_rebuilds} times in {STEPS} steps: the kept list is barely exercised"
    );
    assert_eq!(
        (kept_candidates, kept_rebuilds),
        (fresh_candidates, fresh_rebuilds),
        "candidates tested and grid rebuilds (kept scratch, fresh scratch every step)"
    );
    assert!(
        bits(&kept) == bits(&fresh),
        "bodies differ between a kept scratch and a fresh scratch every step after {STEPS} steps"
    );
    assert_eq!(kept.loads(), fresh.loads(), "loads differ");
    assert_eq!(kept.contacts(), fresh.contacts(), "contact stores differ");
}
