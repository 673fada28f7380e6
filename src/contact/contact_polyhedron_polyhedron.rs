//! Polyhedron–polyhedron contact: bounding spheres, cached separating direction, GJK, EPA, exact fallback.
//!
//! The hot path of the narrow phase. For a pair (A, B) at poses `pos1`, `pos2`:
//! 1. GJK on A ⊖ B in A's frame, warm-started from the pair's cached search direction and support hints
//!    ([`PairCache`]); a separated pair ends here with its exact distance and witness points;
//! 2. EPA for intersecting or touching pairs: Minkowski overlap δ_M, normal n_M, contact points c1, c2;
//! 3. on an iteration cap or a degeneracy of either solver, the exact SAT answer
//!    ([`sat`](super::sat)) with the status saying why, counted in [`QueryCounters`].
//!
//! Classification uses the touching band `touching · L` (L = [`pair_length_scale`] of the two, the smaller
//! body's `length_scale()`): Overlap when
//! δ_M > band, Separated when the gap > band, Touching otherwise (depth and distance then reported as 0).
//!
//! Warm start for persistent contacts: when the pair overlapped at the previous query, EPA first starts
//! from the tetrahedron made of the previous terminal face's three vertex pairs (rebuilt at the new pose from
//! their vertex indices, no support call) and the support point along the opposite of the previous normal.
//! EPA's termination rule makes any closed start polytope safe: once the closest face has a support gap
//! below tolerance and a positive offset, the origin is inside the polytope and the answer is the exact
//! overlap. The warm answer is accepted only when it proves an overlap beyond the touching band; otherwise
//! (the pair separated, or only touches) the cold path (GJK, then EPA) runs.
//!
//! [`intersect_polytopes_cached`] is the boolean variant for rejection tests: bounding spheres, one support
//! call per shape along the cached direction, then GJK stopping at the first separating plane.

use super::counters::QueryCounters;
use super::epa::{epa, EpaOutcome, EpaScratch};
use super::gjk::{gjk, GjkMode, GjkOutcome, Simplex};
use super::minkowski::{MinkowskiPair, SupportPoint, VertexScan};
use super::sat::{sat_polytopes, Polytope};
use super::tolerances::{pair_length_scale, ContactTolerances};
use super::{ContactGeometry, ContactKind, SolverStatus};
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::{ConvexPolyhedron, SupportMap};

/// Up to this many vertices (both shapes) the polyhedron query uses a contiguous linear scan as support
/// map (`VertexScan`) rather than the shapes' hill-climbing; measured faster for 16–64-vertex hulls in
/// `tests/contact_timing.rs`.
pub const SCAN_MAX_VERTICES: usize = 64;

/// What the narrow phase remembers about a pair between queries (frame-1 quantities; small, `Copy`).
#[derive(Copy, Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairCache {
    /// Last GJK search vector (≈ the point of A ⊖ B closest to the origin), in A's frame; zero if none.
    pub dir: Vector,
    /// Support-map hint (vertex index for polyhedra) of A.
    pub hint_a: u32,
    /// Support-map hint (vertex index) of B.
    pub hint_b: u32,
    /// The last overlap's EPA normal (A's frame) and the vertex-index pairs (A, B) of its terminal face:
    /// the next query starts EPA from this face (see the module docs). Valid when `has_face`.
    pub normal: Vector,
    /// Vertex-index pairs (A, B) of the three vertices of the last terminal EPA face.
    pub face: [[u32; 2]; 3],
    /// Whether `normal` and `face` hold a face from an earlier overlap.
    pub has_face: bool,
}

impl PairCache {
    /// Keeps EPA's terminal face (`normal`, frame 1, and its vertex pairs) of an overlap `depth`, and the
    /// search vector the next query starts GJK from: the normal scaled by the depth, at least the
    /// touching band `touch`.
    #[inline(always)]
    fn keep_face(&mut self, depth: Real, normal: &Vector, face: [[u32; 2]; 3], touch: Real) {
        self.dir = -normal * depth.abs().max(touch);
        self.normal = *normal;
        self.face = face;
        self.has_face = true;
    }
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
    ContactGeometry::from_points(
        kind,
        depth,
        distance,
        pos1.rotation * normal1,
        point_a,
        point_b,
        status,
    )
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
    let pos12 = pos1.inv_mul(pos2);
    // Support maps: a contiguous linear scan for particle-sized polyhedra, the shapes' own (hill-climbing)
    // supports beyond.
    let g = if a.vertices().len() <= SCAN_MAX_VERTICES && b.vertices().len() <= SCAN_MAX_VERTICES {
        let (sa, sb) = (
            VertexScan(a.vertex_columns()),
            VertexScan(b.vertex_columns()),
        );
        let mut pair = MinkowskiPair::new(&sa, &sb, &pos12, cache.hint_a, cache.hint_b);
        query_inner(
            pos1, a, pos2, b, &pos12, &mut pair, tol, cache, scratch, counters,
        )
    } else {
        let mut pair = MinkowskiPair::new(a, b, &pos12, cache.hint_a, cache.hint_b);
        query_inner(
            pos1, a, pos2, b, &pos12, &mut pair, tol, cache, scratch, counters,
        )
    };
    counters.record(&g);
    g
}

#[allow(clippy::too_many_arguments)]
fn query_inner<A, B, SA, SB>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    pos12: &Pose,
    pair: &mut MinkowskiPair<'_, SA, SB>,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> ContactGeometry
where
    A: Polytope + ?Sized,
    B: Polytope + ?Sized,
    SA: SupportMap + ?Sized,
    SB: SupportMap + ?Sized,
{
    let scale = pair_length_scale(a.length_scale(), b.length_scale());
    let touch = tol.touching * scale;
    if let Some(g) = warm_hit(pos1, a, b, pos12, pair, tol, cache, scratch, counters) {
        return g;
    }
    cache.has_face = false;
    let v0 = if cache.dir != Vector::zeros() {
        cache.dir
    } else {
        -pos12.translation.vector
    };
    let mut simplex = Simplex::default();
    let gr = gjk(pair, &v0, scale, tol, GjkMode::Distance, &mut simplex);
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
        } => {
            let (kind, status) = (ContactKind::Separated, SolverStatus::Converged);
            geometry_to_world(
                pos1, kind, 0.0, distance, &normal, &point_a, &point_b, status,
            )
        }
        GjkOutcome::Contact => {
            let er = epa(pair, &simplex, scale, tol, scratch);
            counters.epa_runs += 1;
            counters.epa_iterations += er.iterations as u64;
            match er.outcome {
                EpaOutcome::Converged {
                    depth,
                    normal,
                    point_a,
                    point_b,
                    face,
                } => {
                    cache.keep_face(depth, &normal, face, touch);
                    let (kind, d) = if depth > touch {
                        (ContactKind::Overlap, depth)
                    } else {
                        (ContactKind::Touching, 0.0)
                    };
                    let status = SolverStatus::Converged;
                    geometry_to_world(pos1, kind, d, 0.0, &normal, &point_a, &point_b, status)
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

/// Step 2 of the module docs from the warm start alone: when the pair overlapped at its last query
/// (`cache.has_face`) and EPA from the previous terminal face proves an overlap beyond the touching band,
/// the geometry, with the cache updated; `None` otherwise, the cache untouched (the counters count the
/// attempt either way).
#[allow(clippy::too_many_arguments)]
fn warm_hit<A, B, SA, SB>(
    pos1: &Pose,
    a: &A,
    b: &B,
    pos12: &Pose,
    pair: &mut MinkowskiPair<'_, SA, SB>,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> Option<ContactGeometry>
where
    A: Polytope + ?Sized,
    B: Polytope + ?Sized,
    SA: SupportMap + ?Sized,
    SB: SupportMap + ?Sized,
{
    if !cache.has_face {
        return None;
    }
    let scale = pair_length_scale(a.length_scale(), b.length_scale());
    let touch = tol.touching * scale;
    let start = warm_tetrahedron(a, b, pos12, cache, pair)?;
    let er = epa(pair, &start, scale, tol, scratch);
    counters.epa_runs += 1;
    counters.epa_warm_starts += 1;
    counters.epa_iterations += er.iterations as u64;
    let EpaOutcome::Converged {
        depth,
        normal,
        point_a,
        point_b,
        face,
    } = er.outcome
    else {
        return None;
    };
    if depth <= touch {
        return None;
    }
    counters.epa_warm_hits += 1;
    cache.dir = -normal * depth;
    cache.normal = normal;
    cache.face = face;
    cache.hint_a = pair.hint_a;
    cache.hint_b = pair.hint_b;
    Some(geometry_to_world(
        pos1,
        ContactKind::Overlap,
        depth,
        0.0,
        &normal,
        &point_a,
        &point_b,
        SolverStatus::Converged,
    ))
}

/// [`query_polytopes_cached`] when its warm start proves the overlap, B at `pos12` in A's frame (A at
/// `pos1`): `Some` with the same geometry, cache and counters as that query would leave; `None` when the
/// pair did not overlap at its last query or the warm start does not prove the overlap now, with the cache
/// and counters untouched (then the full query answers, as if this had not been called).
#[allow(clippy::too_many_arguments)]
pub fn warm_overlap_polytopes<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    pos1: &Pose,
    pos12: &Pose,
    a: &A,
    b: &B,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> Option<ContactGeometry> {
    if !cache.has_face {
        return None;
    }
    let mut attempt = QueryCounters::default();
    let g = if a.vertices().len() <= SCAN_MAX_VERTICES && b.vertices().len() <= SCAN_MAX_VERTICES {
        let (sa, sb) = (
            VertexScan(a.vertex_columns()),
            VertexScan(b.vertex_columns()),
        );
        let mut pair = MinkowskiPair::new(&sa, &sb, pos12, cache.hint_a, cache.hint_b);
        warm_hit(
            pos1,
            a,
            b,
            pos12,
            &mut pair,
            tol,
            cache,
            scratch,
            &mut attempt,
        )
    } else {
        let mut pair = MinkowskiPair::new(a, b, pos12, cache.hint_a, cache.hint_b);
        warm_hit(
            pos1,
            a,
            b,
            pos12,
            &mut pair,
            tol,
            cache,
            scratch,
            &mut attempt,
        )
    }?;
    counters.polyhedron_polyhedron += 1;
    counters.merge(&attempt);
    counters.record(&g);
    Some(g)
}

/// The warm-start tetrahedron: the previous terminal face rebuilt at the current pose from its vertex
/// indices, plus the support point along the opposite of the previous normal. `None` if an index is out of
/// range (a cache used with other shapes).
fn warm_tetrahedron<A, B, SA, SB>(
    a: &A,
    b: &B,
    pos12: &Pose,
    cache: &PairCache,
    pair: &mut MinkowskiPair<'_, SA, SB>,
) -> Option<Simplex>
where
    A: Polytope + ?Sized,
    B: Polytope + ?Sized,
    SA: SupportMap + ?Sized,
    SB: SupportMap + ?Sized,
{
    let (va, vb) = (a.vertices(), b.vertices());
    let mut s = Simplex::default();
    for (k, [ia, ib]) in cache.face.iter().enumerate() {
        let pa = va.get(*ia as usize)?.coords;
        let pb = (pos12 * vb.get(*ib as usize)?).coords;
        s.pts[k] = SupportPoint {
            w: pa - pb,
            a: pa,
            b: pb,
            ia: *ia,
            ib: *ib,
        };
    }
    s.pts[3] = pair.support(&-cache.normal);
    s.len = 4;
    Some(s)
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
    let scale = pair_length_scale(a.length_scale(), b.length_scale());
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
///
/// `pos1` and `pos2` place A and B in the world (from each shape's principal frame); the answer is in the
/// world frame, with the conventions of [`ContactGeometry`].
///
/// # Example
/// Two unit cubes, B shifted by 0.9 m along x: they overlap by 0.1 m, normal +x.
///
/// ```
/// use polydem::contact::{query_polyhedra, ContactKind};
/// use polydem::math::{Point, Pose, Vector};
/// use polydem::shape::ConvexPolyhedron;
///
/// let corners: Vec<Point> = (0..8)
///     .map(|i| Point::new((i & 1) as f64 - 0.5, ((i >> 1) & 1) as f64 - 0.5, (i >> 2) as f64 - 0.5))
///     .collect();
/// // `frame` places the cube's principal frame in the frame of the corners.
/// let (cube, frame) = ConvexPolyhedron::from_points(&corners)?;
/// let pos1 = frame;
/// let pos2 = Pose::translation(0.9, 0.0, 0.0) * frame;
/// let g = query_polyhedra(&pos1, &cube, &pos2, &cube);
/// assert_eq!(g.kind, ContactKind::Overlap);
/// assert!((g.depth - 0.1).abs() < 1e-9, "depth {}", g.depth);
/// assert!((g.normal - Vector::x()).norm() < 1e-9, "normal {}", g.normal);
/// // c_M is the midpoint of the contact points on A and B.
/// assert!((g.point - Point::from((g.point_a.coords + g.point_b.coords) / 2.0)).norm() < 1e-12);
/// # Ok::<(), polydem::shape::ShapeError>(())
/// ```
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
