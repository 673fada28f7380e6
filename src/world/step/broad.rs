//! Stage 3: the broad phase. The per-body inputs (centres, flags), the grid rebuild when the Verlet skin no
//! longer covers the moves, the candidate list (kept from the last step unless the grid was rebuilt or a
//! dynamic flag changed), and the contact models of the step.

use super::super::region_profile::Section;
use super::super::timing::{Stage, StageClock};
use super::super::world::World;
use super::consensus::RebuildVote;
use super::counters::StepCounters;
use super::laws::effective_models;
use super::params::StepParams;
use super::scratch::StepScratch;

/// Stage 3: the candidate list of this step in `scratch.candidates`.
pub(super) fn stage(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    counters: &mut StepCounters,
) {
    let mut clock = StageClock::start();
    let profile_inputs = clock.serial_start();
    // Per-body inputs of the stages below (centres for the broad phase, flags: dynamic, anisotropic,
    // prescribed, moved half the skin), written by this step's drift pass, else here (the initial
    // evaluation), then folded (see [`super::super::body_inputs`]).
    let inputs = &mut scratch.inputs;
    if !std::mem::take(&mut inputs.fresh) {
        inputs.write(&world.bodies, &world.broad_phase);
    }
    inputs.summarise();
    let summary = inputs.summary;
    let broad = &world.broad_phase;
    // A body beyond half the skin does not rebuild by itself: the lists stay valid while the two largest
    // moves sum to less than the skin (`BroadPhase::pairs_may_be_stale`, scanned only then).
    let forced = !params.skips.verlet_skin
        || broad.rebuilds() == 0
        || broad.centres_at_build().len() != inputs.centres.len()
        || broad.walls_moved(&world.walls);
    let rebuild = match &scratch.consensus {
        None => {
            forced || (summary.any_far && broad.pairs_may_be_stale(&inputs.centres, &world.walls))
        }
        // A part of a world split over processes takes the decision of the whole world.
        Some(consensus) => consensus.decide(&RebuildVote {
            forced,
            any_far: summary.any_far,
            largest_moves_sq: broad.largest_moves_sq(&inputs.centres, |i| world.counts_body(i)),
            broad_phase: broad,
            walls: &world.walls,
        }),
    };
    let broad = &mut world.broad_phase;
    clock.serial_end(Section::SerialInputs, profile_inputs);
    if rebuild {
        broad.rebuild_with_walls_timed(&inputs.centres, &world.radii, &world.walls, &mut clock);
        counters.broad_rebuilds += 1;
    }
    let profile_inputs = clock.serial_start();
    // The candidate list: kept from the last step unless the grid was rebuilt or a dynamic flag changed.
    inputs.update_candidates(
        broad,
        params.skips.non_dynamic_pairs,
        &mut scratch.candidates,
    );
    counters.body_pairs_tested += inputs.body_candidates as u64;
    let wall_pairs = inputs.wall_candidates as u64;
    counters.wall_pairs_tested += wall_pairs;
    counters.wall_pairs_rejected += summary.dynamic as u64 * world.walls.len() as u64 - wall_pairs;
    scratch.any_prescribed = summary.any_prescribed;
    // The contact models of every material pair with the skips applied, once per step.
    effective_models(&world.materials, &params.skips, &mut scratch.models);
    clock.serial_end(Section::SerialInputs, profile_inputs);
    counters.add(Stage::Broad, clock.stop());
}
