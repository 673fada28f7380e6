//! Counters of the narrow phase: how many queries of each kind ran, how many solver iterations they took and
//! how often the exact fallback was needed, and why.
//!
//! The caller owns a [`QueryCounters`] and passes it by `&mut` to the hot-path queries; nothing is global.
//! Counters of several threads are combined with [`QueryCounters::merge`].

use std::fmt;

/// Per-caller statistics of contact queries.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct QueryCounters {
    /// Polyhedron–polyhedron queries answered.
    pub polyhedron_polyhedron: u64,
    /// Sphere–sphere queries answered.
    pub sphere_sphere: u64,
    /// Sphere–plane queries answered.
    pub sphere_plane: u64,
    /// Polyhedron–plane queries answered.
    pub polyhedron_plane: u64,
    /// Sphere–polyhedron queries answered.
    pub sphere_polyhedron: u64,
    /// Queries through the generic support-map arm (a pair with a curved shape other than two spheres).
    /// This and the next two counters are not serialised, so that checkpoints and reports keep their
    /// format.
    #[serde(skip)]
    pub support_map: u64,
    /// Queries of a curved shape (other than a sphere) against a plane.
    #[serde(skip)]
    pub convex_plane: u64,
    /// Generic-arm queries whose depth bounds did not meet `curved_gap` (cap or degeneracy): answered with
    /// the best bound and a fallback status, also counted in the fallback counters.
    #[serde(skip)]
    pub support_map_unconverged: u64,
    /// Pairs rejected by the bounding spheres before any support call.
    pub bounding_sphere_rejections: u64,
    /// Pairs rejected by the cached separating direction (one support call per shape).
    pub cached_axis_rejections: u64,
    /// Pairs whose cached-axis test was skipped because their motion since it last proved them separated
    /// cannot have closed the gap (`crate::world::skips::still_separated`; no support call).
    pub motion_bound_skips: u64,
    /// GJK runs.
    pub gjk_runs: u64,
    /// Total GJK iterations over `gjk_runs`.
    pub gjk_iterations: u64,
    /// EPA runs.
    pub epa_runs: u64,
    /// Total EPA iterations over `epa_runs`.
    pub epa_iterations: u64,
    /// EPA runs started from the pair's previous terminal face, and how many of them proved the overlap
    /// (the others continued on the cold path).
    pub epa_warm_starts: u64,
    /// Warm-started EPA runs that proved the overlap from the previous face.
    pub epa_warm_hits: u64,
    /// Exact SAT fallbacks after GJK or EPA hit its iteration cap.
    pub fallback_max_iterations: u64,
    /// Exact SAT fallbacks after GJK or EPA met a degenerate configuration (flat start, broken horizon,
    /// buffer full).
    pub fallback_degenerate: u64,
    /// Queries that ended [`Overlap`](super::ContactKind::Overlap).
    pub overlapping: u64,
    /// Queries that ended [`Touching`](super::ContactKind::Touching).
    pub touching: u64,
    /// Queries that ended [`Separated`](super::ContactKind::Separated).
    pub separated: u64,
}

impl QueryCounters {
    /// Adds the counts of `other` (e.g. of another thread) to `self`.
    pub fn merge(&mut self, other: &QueryCounters) {
        self.polyhedron_polyhedron += other.polyhedron_polyhedron;
        self.sphere_sphere += other.sphere_sphere;
        self.sphere_plane += other.sphere_plane;
        self.polyhedron_plane += other.polyhedron_plane;
        self.sphere_polyhedron += other.sphere_polyhedron;
        self.support_map += other.support_map;
        self.convex_plane += other.convex_plane;
        self.support_map_unconverged += other.support_map_unconverged;
        self.bounding_sphere_rejections += other.bounding_sphere_rejections;
        self.cached_axis_rejections += other.cached_axis_rejections;
        self.motion_bound_skips += other.motion_bound_skips;
        self.gjk_runs += other.gjk_runs;
        self.gjk_iterations += other.gjk_iterations;
        self.epa_runs += other.epa_runs;
        self.epa_iterations += other.epa_iterations;
        self.epa_warm_starts += other.epa_warm_starts;
        self.epa_warm_hits += other.epa_warm_hits;
        self.fallback_max_iterations += other.fallback_max_iterations;
        self.fallback_degenerate += other.fallback_degenerate;
        self.overlapping += other.overlapping;
        self.touching += other.touching;
        self.separated += other.separated;
    }

    /// Total number of exact fallbacks.
    pub fn fallbacks(&self) -> u64 {
        self.fallback_max_iterations + self.fallback_degenerate
    }

    /// Records the kind of a finished query's result.
    pub(crate) fn record(&mut self, g: &super::ContactGeometry) {
        match g.kind {
            super::ContactKind::Overlap => self.overlapping += 1,
            super::ContactKind::Touching => self.touching += 1,
            super::ContactKind::Separated => self.separated += 1,
        }
        match g.status {
            super::SolverStatus::FallbackAfterMaxIterations => self.fallback_max_iterations += 1,
            super::SolverStatus::FallbackAfterDegenerate => self.fallback_degenerate += 1,
            _ => {}
        }
    }
}

impl fmt::Display for QueryCounters {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let per = |n: u64, d: u64| if d == 0 { 0.0 } else { n as f64 / d as f64 };
        writeln!(
            f,
            "queries: polyhedron-polyhedron {}, sphere-sphere {}, sphere-plane {}, polyhedron-plane {}, sphere-polyhedron {}",
            self.polyhedron_polyhedron,
            self.sphere_sphere,
            self.sphere_plane,
            self.polyhedron_plane,
            self.sphere_polyhedron
        )?;
        writeln!(
            f,
            "results: overlap {}, touching {}, separated {}; early rejections: bounding sphere {}, cached axis {}, motion bound {}",
            self.overlapping,
            self.touching,
            self.separated,
            self.bounding_sphere_rejections,
            self.cached_axis_rejections,
            self.motion_bound_skips
        )?;
        writeln!(
            f,
            "gjk: {} runs, {:.2} iterations/run; epa: {} runs, {:.2} iterations/run, {} warm starts ({} proved the overlap)",
            self.gjk_runs,
            per(self.gjk_iterations, self.gjk_runs),
            self.epa_runs,
            per(self.epa_iterations, self.epa_runs),
            self.epa_warm_starts,
            self.epa_warm_hits
        )?;
        write!(
            f,
            "exact fallbacks: {} after max iterations, {} after degeneracy",
            self.fallback_max_iterations, self.fallback_degenerate
        )?;
        // Written only for worlds with curved shapes, so the summary of others reads as before.
        if self.support_map + self.convex_plane > 0 {
            write!(
                f,
                "\nsupport-map arm: {} queries ({} unconverged, answered with their bounds), curved-plane {}",
                self.support_map, self.support_map_unconverged, self.convex_plane
            )?;
        }
        Ok(())
    }
}
