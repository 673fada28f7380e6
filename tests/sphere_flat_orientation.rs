//! The flat sphere path with its orientation tracking off (`SphereSim::set_track_orientation(false)`)
//! moves the spheres exactly as with it on: a sphere's orientation enters no force, torque or motion of
//! the path (isotropic spheres, ω = L/J), so positions, velocities, angular momenta, loads and springs
//! are the same bits; only the orientations stay where they were.
//!
//! Scene: sphere bed a (`scenes/sphere_bed_a_hertz_5ms.toml`: Hertz–Mindlin with friction, so the
//! spheres spin), its first 300 steps (the ball lands at step ~50).

#[path = "support/world_bits.rs"]
#[allow(dead_code)]
mod world_bits;

use std::path::Path;

use polydem::scene::load_scene;
use polydem::world::{SphereSim, World};

const STEPS: u64 = 300;

fn run(track: bool) -> (World, World) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_bed_a_hertz_5ms.toml");
    let mut sim = load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    sim.params.energy_ledger = false;
    let mut flat = SphereSim::from_world(&sim.world, &sim.params)
        .unwrap_or_else(|e| panic!("the sphere bed must take the flat path: {e}"));
    flat.set_track_orientation(track);
    for _ in 0..STEPS {
        flat.step().unwrap_or_else(|e| panic!("flat step: {e}"));
    }
    let mut world = sim.world.clone();
    flat.write_back(&mut world);
    (sim.world, world)
}

#[test]
fn orientation_tracking_changes_nothing_but_the_orientations() {
    let (start, tracked) = run(true);
    let (_, frozen) = run(false);
    let mut spun = 0;
    for (i, ((a, b), s)) in tracked
        .bodies()
        .iter()
        .zip(frozen.bodies())
        .zip(start.bodies())
        .enumerate()
    {
        let bits = |b: &polydem::dynamics::RigidBody| {
            b.position
                .iter()
                .chain(b.velocity.iter())
                .chain(b.angular_momentum.iter())
                .map(|x| x.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(
            bits(a),
            bits(b),
            "body {i} after {STEPS} steps: position, velocity, L tracked {:?} {:?} {:?}, \
             untracked {:?} {:?} {:?} (must be the same bits)",
            a.position,
            a.velocity,
            a.angular_momentum,
            b.position,
            b.velocity,
            b.angular_momentum
        );
        assert_eq!(
            b.orientation, s.orientation,
            "body {i}: the untracked orientation moved from {:?} to {:?}",
            s.orientation, b.orientation
        );
        if a.orientation != s.orientation {
            spun += 1;
        }
    }
    let (la, lb) = (
        world_bits::load_values(&tracked, &[tracked.time()]),
        world_bits::load_values(&frozen, &[frozen.time()]),
    );
    if let Some((k, x, y)) = world_bits::first_value_difference(&la, &lb) {
        panic!(
            "loads differ at value {k} of {}: tracked {x}, untracked {y}",
            la.len()
        );
    }
    assert!(
        tracked.contacts() == frozen.contacts(),
        "the written-back contact stores (springs, forces) differ"
    );
    // The comparison must be able to fail: with tracking on, spheres did turn.
    assert!(
        spun > 100,
        "only {spun} spheres turned in {STEPS} tracked steps: expected > 100 for a test that can fail"
    );
}
