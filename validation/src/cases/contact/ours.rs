//! The calls into polydem's contact core used by the case, in one place.

use polydem::contact::{
    intersect_polyhedra_cached, query_polyhedra_with, sat_polyhedra, ContactGeometry,
    ContactTolerances, EpaScratch, PairCache, QueryCounters,
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
    sat_polyhedra(pos1, a, pos2, b)
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
        query_polyhedra_with(
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

    /// Boolean intersection test from a cold pair cache (separated-pair rejection), default tolerances.
    pub fn intersects(
        &mut self,
        pos1: &Pose,
        a: &ConvexPolyhedron,
        pos2: &Pose,
        b: &ConvexPolyhedron,
    ) -> bool {
        let mut cache = PairCache::default();
        intersect_polyhedra_cached(pos1, a, pos2, b, &mut cache, &mut self.counters)
    }
}
