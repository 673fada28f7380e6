//! Polyhedron–polyhedron contact: bounding spheres, cached separating direction, GJK, EPA, exact fallback.
//!
//! The hot path of the narrow phase. For a pair (A, B) at poses `pos1`, `pos2`:
//! 1. GJK on A ⊖ B in A's frame, warm-started from the pair's cached search direction and support hints
//!    ([`PairCache`]); a separated pair ends here with its exact distance and witness points;
//! 2. EPA for intersecting or touching pairs: Minkowski overlap δ_M, normal n_M, contact points c1, c2;
//! 3. on an iteration cap or a degeneracy of either solver, the exact SAT answer
//!    ([`sat`](super::sat)) with the status saying why, counted in [`QueryCounters`].
//!
//! Classification uses the touching band `touching · L` (L = the larger `length_scale()` of the two): Overlap when
//! δ_M > band, Separated when the gap > band, Touching otherwise (depth and distance then reported as 0).
//!
//! [`intersect_polytopes_cached`] is the boolean variant for rejection tests: bounding spheres, one support
//! call per shape along the cached direction, then GJK stopping at the first separating plane.

use super::counters::QueryCounters;
use super::epa::{epa, EpaOutcome, EpaScratch};
use super::gjk::{gjk, GjkMode, GjkOutcome, Simplex};
use super::minkowski::MinkowskiPair;
use super::sat::{sat_polytopes, Polytope};
use super::tolerances::ContactTolerances;
use super::{ContactGeometry, ContactKind, SolverStatus};
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::ConvexPolyhedron;

/// What the narrow phase remembers about a pair between queries (frame-1 quantities; tiny, `Copy`).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct PairCache {
    /// Last GJK search vector (≈ the point of A ⊖ B closest to the origin), in A's frame; zero if none.
    pub dir: Vector,
    /// Support-map hints (vertex indices for polyhedra) of A and B.
    pub hint_a: u32,
    pub hint_b: u32,
}

/// Converts frame-1 features to a world-frame [`ContactGeometry`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn geometry_to_world(
    pos1: &Pose,
    kind: ContactKind,
    depth: Real,
    distance: Real,
    normal1: &Vector,
    point_a1: &Vector,
    point_b1: &Vector,
    status: SolverStatus,
) -> ContactGeometry {
    let point_a = pos1 * Point::from(*point_a1);
    let point_b = pos1 * Point::from(*point_b1);
    ContactGeometry {
        kind,
        depth,
        distance,
        normal: pos1.rotation * normal1,
        point_a,
        point_b,
        point: nalgebra::center(&point_a, &point_b),
        status,
    }
}

/// Full contact query between two polytopes (hot path): see the module docs.
#[allow(clippy::too_many_arguments)]
pub fn query_polytopes_cached<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> ContactGeometry {
    counters.polyhedron_polyhedron += 1;
    let g = query_inner(pos1, a, pos2, b, tol, cache, scratch, counters);
    counters.record(&g);
    g
}

#[allow(clippy::too_many_arguments)]
fn query_inner<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> ContactGeometry {
    let pos12 = pos1.inv_mul(pos2);
    let scale = a.length_scale().max(b.length_scale());
    let touch = tol.touching * scale;
    let mut pair = MinkowskiPair::new(a, b, &pos12, cache.hint_a, cache.hint_b);
    let v0 = if cache.dir != Vector::zeros() {
        cache.dir
    } else {
        -pos12.translation.vector
    };
    let mut simplex = Simplex::default();
    let gr = gjk(&mut pair, &v0, scale, tol, GjkMode::Distance, &mut simplex);
    counters.gjk_runs += 1;
    counters.gjk_iterations += gr.iterations as u64;
    cache.dir = gr.v;
    let fallback = |status| sat_polytopes(pos1, a, pos2, b, tol, status);
    let result = match gr.outcome {
        GjkOutcome::Separated {
            distance,
            normal,
            point_a,
            point_b,
        } => geometry_to_world(
            pos1,
            ContactKind::Separated,
            0.0,
            distance,
            &normal,
            &point_a,
            &point_b,
            SolverStatus::Converged,
        ),
        GjkOutcome::Contact => {
            let er = epa(&mut pair, &simplex, scale, tol, scratch);
            counters.epa_runs += 1;
            counters.epa_iterations += er.iterations as u64;
            match er.outcome {
                EpaOutcome::Converged {
                    depth,
                    normal,
                    point_a,
                    point_b,
                } => {
                    cache.dir = -normal * depth.abs().max(touch);
                    let (kind, d) = if depth > touch {
                        (ContactKind::Overlap, depth)
                    } else {
                        (ContactKind::Touching, 0.0)
                    };
                    geometry_to_world(
                        pos1,
                        kind,
                        d,
                        0.0,
                        &normal,
                        &point_a,
                        &point_b,
                        SolverStatus::Converged,
                    )
                }
                EpaOutcome::MaxIterations => fallback(SolverStatus::FallbackAfterMaxIterations),
                EpaOutcome::Degenerate(_why) => {
                    #[cfg(test)]
                    if std::env::var("POLYDEM_DEBUG_FALLBACK").is_ok() {
                        eprintln!(
                            "epa degenerate: {_why:?} after {} iterations",
                            er.iterations
                        );
                    }
                    fallback(SolverStatus::FallbackAfterDegenerate)
                }
            }
        }
        GjkOutcome::MaxIterations | GjkOutcome::SeparatingAxis => {
            fallback(SolverStatus::FallbackAfterMaxIterations)
        }
    };
    cache.hint_a = pair.hint_a;
    cache.hint_b = pair.hint_b;
    result
}

/// Whether two polytopes overlap or touch (within the touching band), without measuring: bounding spheres,
/// the cached separating direction, then GJK stopping at the first separating plane. A GJK iteration cap
/// falls back to the exact SAT answer (counted).
pub fn intersect_polytopes_cached<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    counters: &mut QueryCounters,
) -> bool {
    let pos12 = pos1.inv_mul(pos2);
    let (ra, rb) = (a.bounding_radius(), b.bounding_radius());
    let scale = a.length_scale().max(b.length_scale());
    let touch = tol.touching * scale;
    let t12 = pos12.translation.vector;
    if t12.norm_squared() > (ra + rb + touch) * (ra + rb + touch) {
        counters.bounding_sphere_rejections += 1;
        return false;
    }
    let mut pair = MinkowskiPair::new(a, b, &pos12, cache.hint_a, cache.hint_b);
    if cache.dir != Vector::zeros() {
        // h_A(n) + h_B(−n) < −band along n = −v̂ proves separation.
        let n = -cache.dir.normalize();
        let (s, _) = pair.overlap_along(&n);
        if s < -touch {
            counters.cached_axis_rejections += 1;
            cache.hint_a = pair.hint_a;
            cache.hint_b = pair.hint_b;
            return false;
        }
    }
    let v0 = if cache.dir != Vector::zeros() {
        cache.dir
    } else {
        -t12
    };
    let mut simplex = Simplex::default();
    let gr = gjk(&mut pair, &v0, scale, tol, GjkMode::Boolean, &mut simplex);
    counters.gjk_runs += 1;
    counters.gjk_iterations += gr.iterations as u64;
    cache.hint_a = pair.hint_a;
    cache.hint_b = pair.hint_b;
    cache.dir = gr.v;
    match gr.outcome {
        GjkOutcome::SeparatingAxis => false,
        GjkOutcome::Separated { .. } => false,
        GjkOutcome::Contact => true,
        GjkOutcome::MaxIterations => {
            counters.fallback_max_iterations += 1;
            let g = sat_polytopes(
                pos1,
                a,
                pos2,
                b,
                tol,
                SolverStatus::FallbackAfterMaxIterations,
            );
            g.kind != ContactKind::Separated
        }
    }
}

/// Contact query between two convex polyhedra with a fresh cache, fresh scratch, default tolerances and no
/// counters: the convenience form (CLI, tests). The answer is the same as the hot path's.
pub fn query_polyhedra(
    pos1: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
) -> ContactGeometry {
    let mut cache = PairCache::default();
    let mut counters = QueryCounters::default();
    EPA_SCRATCH.with(|s| {
        query_polytopes_cached(
            pos1,
            a,
            pos2,
            b,
            &ContactTolerances::default(),
            &mut cache,
            &mut s.borrow_mut(),
            &mut counters,
        )
    })
}

thread_local! {
    static EPA_SCRATCH: std::cell::RefCell<EpaScratch> = std::cell::RefCell::new(EpaScratch::default());
}

/// Hot-path contact query between two convex polyhedra with the default tolerances: the caller keeps one
/// [`PairCache`] per pair, one [`EpaScratch`] per thread and one [`QueryCounters`] per thread.
pub fn query_polyhedra_cached(
    pos1: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> ContactGeometry {
    query_polytopes_cached(
        pos1,
        a,
        pos2,
        b,
        &ContactTolerances::default(),
        cache,
        scratch,
        counters,
    )
}

/// [`query_polyhedra_cached`] with explicit tolerances (for tolerance sweeps).
#[allow(clippy::too_many_arguments)]
pub fn query_polyhedra_with(
    pos1: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> ContactGeometry {
    query_polytopes_cached(pos1, a, pos2, b, tol, cache, scratch, counters)
}

/// Whether two convex polyhedra overlap or touch, without measuring (rejection test; default tolerances).
pub fn intersect_polyhedra_cached(
    pos1: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
    cache: &mut PairCache,
    counters: &mut QueryCounters,
) -> bool {
    intersect_polytopes_cached(
        pos1,
        a,
        pos2,
        b,
        &ContactTolerances::default(),
        cache,
        counters,
    )
}

/// The exact SAT answer for two convex polyhedra (the oracle; status `Exact`). Slow: O(E_A E_B V).
pub fn sat_polyhedra(
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
