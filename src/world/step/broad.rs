//! Stage 3: the broad phase. The per-body inputs (centres, flags), the grid rebuild when the Verlet skin no
//! longer covers the moves, the candidate list (kept from the last step unless the grid was rebuilt or a
//! dynamic flag changed), and the contact models of the step.

use crate::math::Point;

use super::super::broad_phase::BroadPhase;
use super::super::region_profile::Section;
use super::super::timing::{Stage, StageClock};
use super::super::world::{Wall, World};
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
    let broad = &mut world.broad_phase;
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
            centres: &inputs.centres,
            broad_phase: broad,
            walls: &world.walls,
        }),
    };
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

/// What one part of a world split over processes knows of the rebuild decision at its stage 3.
#[derive(Debug)]
pub struct RebuildVote<'a> {
    /// A rebuild is due whatever the moves (first build, body count, walls moved half the skin, skin off).
    pub forced: bool,
    /// Some body of the part moved more than half the skin since the last build.
    pub any_far: bool,
    /// The part's body centres now.
    pub centres: &'a [Point],
    /// The part's broad phase (its build positions and skin).
    pub broad_phase: &'a BroadPhase,
    /// The walls now.
    pub walls: &'a [Wall],
}

/// Takes the broad-phase rebuild decision of a world split over several processes: every part must
/// rebuild exactly when one process stepping the whole world would (see `crate::world::distributed`).
/// One call per stage 3 on every part, in the same order (an implementation may communicate).
pub trait RebuildConsensus: std::fmt::Debug + Send + Sync {
    /// Whether the broad phase is rebuilt now.
    fn decide(&self, vote: &RebuildVote<'_>) -> bool;
}
