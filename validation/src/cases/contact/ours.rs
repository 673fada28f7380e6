//! The calls into polydem's contact core used by the case, in one place.

use polydem::contact::{
    intersect_polytopes_cached, query_polytopes_cached, sat_polytopes, ContactGeometry,
    ContactTolerances, EpaScratch, PairCache, QueryCounters, SolverStatus,
};
use polydem::math::Pose;
use polydem::shape::ConvexPolyhedron;

/// The exact SAT oracle (reference answer).
pub fn sat(
    pos1: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
) -> ContactGeometry {
    sat_polytopes(
        pos1,
        a,
        pos2,
        b,
        &ContactTolerances::default(),
        SolverStatus::Exact,
    )
}

/// Our state for a run of queries: tolerances, EPA scratch, counters.
pub struct Ours {
    pub tol: ContactTolerances,
    pub scratch: EpaScratch,
    pub counters: QueryCounters,
}

impl Ours {
    pub fn new(tol: ContactTolerances) -> Self {
        Ours {
            tol,
            scratch: EpaScratch::new(&tol),
            counters: QueryCounters::default(),
        }
    }

    /// GJK/EPA contact query from a cold pair cache (what the first step of a new contact costs).
    pub fn query(
        &mut self,
        pos1: &Pose,
        a: &ConvexPolyhedron,
        pos2: &Pose,
        b: &ConvexPolyhedron,
    ) -> ContactGeometry {
        let mut cache = PairCache::default();
        query_polytopes_cached(
            pos1,
            a,
            pos2,
            b,
            &self.tol,
            &mut cache,
            &mut self.scratch,
            &mut self.counters,
        )
    }

    /// Boolean intersection test from a cold pair cache (separated-pair rejection).
    pub fn intersects(
        &mut self,
        pos1: &Pose,
        a: &ConvexPolyhedron,
        pos2: &Pose,
        b: &ConvexPolyhedron,
    ) -> bool {
        let mut cache = PairCache::default();
        intersect_polytopes_cached(pos1, a, pos2, b, &self.tol, &mut cache, &mut self.counters)
    }
}
