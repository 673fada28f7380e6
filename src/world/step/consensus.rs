//! The seam through which a world split over several processes takes stage 3's rebuild decision
//! together: what one part knows ([`RebuildVote`]) and who decides ([`RebuildConsensus`]). A leaf file,
//! so that the stage and the scratch that holds the consensus both use it without using each other.

use crate::math::Real;

use super::super::broad_phase::BroadPhase;
use super::super::world::Wall;

/// What one part of a world split over processes knows of the rebuild decision at its stage 3.
#[derive(Debug)]
pub struct RebuildVote<'a> {
    /// A rebuild is due whatever the moves (first build, body count, walls moved half the skin, skin off).
    pub forced: bool,
    /// Some body of the part moved more than half the skin since the last build.
    pub any_far: bool,
    /// The two largest squared moves (m², the largest first) since the last build among the bodies the
    /// part counts as its own ([`World::count_only`](crate::world::World::count_only); all without it).
    pub largest_moves_sq: (Real, Real),
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
