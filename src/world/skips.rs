//! Work the step skips because the scene does not need it, each switchable so that a benchmark can measure
//! it and a test can compare on against off (`tests/world_skips.rs`, `benches/step.rs`).
//!
//! | switch | what is skipped | equivalence with the switch off |
//! |---|---|---|
//! | `bounding_spheres` | the query of a body pair whose bounding spheres are apart by more than the touching band, and of a body–wall pair whose bounding sphere does not reach the plane | same forces; the pair's GJK warm start is not refreshed, so later EPA answers of that pair may differ at the solver tolerance |
//! | `cached_axis` | GJK for a polyhedron pair still separated along its cached separating direction (one support call per shape) | as above |
//! | `motion_bound` | the cached-axis test itself, while the motion of the pair since that test last proved the separation cannot have closed the gap it measured (no vertex is read; see below) | exact: the skipped test would have rejected the pair; bit-identical bodies, loads, wall forces and ledger |
//! | `warm_overlap` | the cached-axis test of a polyhedron pair that overlapped at its last query, when the warm-started EPA (run first) proves that it still overlaps: the support function of A ⊖ B along any direction is at least the Minkowski overlap, so the test cannot reject such a pair | exact: the same query answers as after the failed test (bit-identical bodies, loads, ledger, store); a warm start that does not prove the overlap runs again in the full query (≈ 0.1 % of the contacts) |
//! | `verlet_skin` | broad-phase rebuilds only when the two largest moves since the last one sum to the skin (one body alone may travel nearly the whole skin) | exact: the pair list only differs by pairs whose bounding spheres are farther apart than the skin |
//! | `frictionless_history` | the tangential spring of pairs with μ = 0 (its force is zero: the Coulomb cap is 0) | bit-identical bodies and forces (up to the sign of zero); the stored history stays empty |
//! | `undamped_contacts` | the damping term of a viscous law whose coefficient is 0 (e = 1); e = 1 already maps to `DampingLaw::None`, which costs nothing | bit-identical (up to the sign of zero) |
//! | `still_rotation` | the rotation drift of a dynamic body whose angular momentum is exactly zero | to the round-off of one quaternion renormalisation (≤ 2⁻⁵² relative) per step |
//! | `isotropic_rotation` | the five sub-rotations of the splitting for a body whose principal moments are exactly equal (a sphere): its free rotation is one turn about the constant L by the angle Δt|L|/J, done as one quaternion product, and ω = L/J without the two frame changes | not bit-identical: the splitting is only second order for such a body (its sub-flows do not commute), the single turn is its exact flow (in the Cayley form, the same modified angle 4 atan(θ/4) as the paper's sub-steps); ω differs at round-off. Bounded in `tests/world_isotropic.rs` |
//! | `sphere_kernel` | the general pair dispatch for candidates whose sides are spheres or a wall and a sphere: per-body inputs gathered once per step, the closed forms and the law called directly (`src/world/step/sphere_kernel.rs`); in a world of free spheres, also the per-body tests of the integration (`src/world/step/sphere.rs`) | exact: the same operations in the same order, bit-identical bodies, loads, ledger and contact store |
//! | `non_dynamic_pairs` | queries between two non-dynamic bodies (fixed or prescribed) and the integration of fixed bodies | forces between two non-dynamic bodies are not computed: they act on nothing that moves, but the force reported on such a body omits them |
//!
//! Rejected pairs are stored as `Separated` with `distance` a lower bound of the true gap (the gap of the
//! bounding spheres, or the separation along the cached axis) and witness points on that bound, not the
//! exact closest points; no later stage reads them. A pair skipped by the motion bound keeps the geometry
//! of its last test (a lower bound of the gap at that time).
//!
//! # The motion bound
//! The cached-axis test of a polyhedron pair (A, B) evaluates, in A's frame, the overlap along the fixed
//! unit vector n = −v̂ of the cache: s = h_A(n) + h_B(−n), and rejects the pair when s < −band. In A's
//! frame h_A(n) never changes; h_B(−n) = −min_j n·q_j over B's vertices q_j = R₁₂ v_j + t₁₂ placed by the
//! pose of B relative to A (`pos12`). Between two relative poses, every q_j moves by at most
//! |Δt₁₂| + 2 sin(φ/2) |v_j| (φ the angle of the relative rotation between them), so s grows by at most
//! Δ = |Δt₁₂| + 2 sin(φ/2) R_B with R_B the bounding radius of B about its centre. When the test rejects
//! the pair, the store keeps `pos12` and the gap g = −s (less a rounding margin of 1e-9 of the size of the
//! pair and its distance: the test's round-off is ~1e-15 of that); at a later step, while Δ + band < g,
//! the test would reject again (same n: the cache does not change while the pair is rejected), so it is
//! skipped. The check reads the two poses only (about a hundred instructions against ~1.5e3 for the two
//! support scans). The bound uses the *net* relative motion, so two rocks falling side by side, or a bed
//! vibrating in place, stay skipped for as long as they do not approach each other.
//!
//! What the skipped test would have written, and why nothing reads it: the `Separated` geometry (a lower
//! bound; see above: the law resets a separated pair's history and forces whatever its distance, and no
//! observer reads a separated pair's geometry), `has_face = false` (already false: a stored proof is dropped
//! by every query that could set it), and the support hints of both shapes. The hints are the only input
//! a later query takes from them, and the bound is kept only for pairs whose shapes both use the full
//! vertex scan (`VertexScan`, at most `SCAN_MAX_VERTICES` vertices), which ignores the incoming hint: so
//! a later query, the pair smoothing (which reads the hints that query left) and the forces are the same
//! bits. `tests/world_skip_motion_bound.rs` checks the bound against the exact test over random motions
//! and the trajectories of a polyhedral bed with the switch on and off.
//!
//! # Effect
//! The trajectories, packing traces and penetration monitors of `polydem rockfill` are byte-identical with
//! and without the two skips; they cut the instructions of the rockfill packing by about a quarter and of
//! a 10⁴-polyhedra step by about a quarter (counts and commands: `docs/tuning.md`).

use crate::contact::contact_polyhedron_polyhedron::SCAN_MAX_VERTICES;
use crate::contact::minkowski::{MinkowskiPair, VertexScan};
use crate::contact::{
    warm_overlap_with, ContactGeometry, ContactKind, ContactTolerances, EpaScratch, PairCache,
    QueryCounters, SolverStatus,
};
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::{ConvexPolyhedron, Shape, SupportMap};

use super::contact_store::ContactState;
pub use super::separation_bound::SeparationBound;

/// The switches of the step's skips (see the module docs); all on by default: each is exact or changes
/// nothing beyond the solver tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Skips {
    /// Skip a pair query whose bounding spheres are apart.
    pub bounding_spheres: bool,
    /// Skip GJK for a polyhedron pair still separated along its cached axis.
    pub cached_axis: bool,
    /// Skip the cached-axis test while the pair's motion cannot have closed the gap.
    pub motion_bound: bool,
    /// Skip the cached-axis test of a pair whose warm-started EPA proves it still overlaps.
    pub warm_overlap: bool,
    /// Rebuild the broad phase only when the bodies' moves reach the skin.
    pub verlet_skin: bool,
    /// Keep no tangential history for frictionless pairs.
    pub frictionless_history: bool,
    /// Skip the damping term of a law whose coefficient is zero.
    pub undamped_contacts: bool,
    /// Skip the rotation drift of a body with zero angular momentum.
    pub still_rotation: bool,
    /// Turn a body with equal principal moments in one exact rotation.
    pub isotropic_rotation: bool,
    /// Skip queries between two non-dynamic bodies and the integration of fixed bodies.
    pub non_dynamic_pairs: bool,
    /// Evaluate sphere–sphere and sphere–wall pairs with the closed forms and the law directly.
    pub sphere_kernel: bool,
}

impl Default for Skips {
    fn default() -> Self {
        Self::all(true)
    }
}

impl Skips {
    /// Every skip on (`true`) or off.
    pub fn all(on: bool) -> Self {
        Self {
            bounding_spheres: on,
            cached_axis: on,
            motion_bound: on,
            warm_overlap: on,
            verlet_skin: on,
            frictionless_history: on,
            undamped_contacts: on,
            still_rotation: on,
            isotropic_rotation: on,
            non_dynamic_pairs: on,
            sphere_kernel: on,
        }
    }
}

/// A separated geometry with the lower bound `gap` of the distance, normal `normal` (A → B) and witness
/// points on that bound.
fn separated(gap: Real, normal: Vector, point_a: Point, point_b: Point) -> ContactGeometry {
    ContactGeometry::from_points(
        ContactKind::Separated,
        0.0,
        gap.max(0.0),
        normal,
        point_a,
        point_b,
        SolverStatus::Converged,
    )
}

/// The bounding-sphere rejection of two bodies: `Some(separated)` when the spheres (centres `xa`, `xb`,
/// radii `ra`, `rb`) are apart by more than the touching band of the pair (`tol.touching` times the larger
/// length scale `scale`).
pub fn reject_by_bounding_spheres(
    xa: &Point,
    ra: Real,
    xb: &Point,
    rb: Real,
    scale: Real,
    tol: &ContactTolerances,
    counters: &mut QueryCounters,
) -> Option<ContactGeometry> {
    let d = xb - xa;
    let reach = ra + rb + tol.touching * scale;
    let dist_sq = d.norm_squared();
    if dist_sq <= reach * reach {
        return None;
    }
    counters.bounding_sphere_rejections += 1;
    counters.separated += 1;
    let dist = dist_sq.sqrt();
    let n = d / dist;
    Some(separated(dist - ra - rb, n, xa + n * ra, xb - n * rb))
}

/// The bounding-sphere rejection of a body against a wall: `Some(separated)` when the body's bounding
/// sphere (centre `x`, radius `r`) does not reach the plane (signed distance `distance` ≥ r: the body
/// cannot touch it). The wall is A, `normal` its world normal. The step's body–wall list has a skin, so it
/// holds such pairs; this keeps the exact query for those that can touch.
pub fn reject_wall_by_bounding_sphere(
    distance: Real,
    normal: &Vector,
    x: &Point,
    r: Real,
    counters: &mut QueryCounters,
) -> Option<ContactGeometry> {
    if distance < r {
        return None;
    }
    counters.bounding_sphere_rejections += 1;
    counters.separated += 1;
    Some(separated(
        distance - r,
        *normal,
        x - normal * distance,
        x - normal * r,
    ))
}

/// The skips of a polyhedron pair (A at `pose_a`, B at `pose_b`) before its full query, in this order: the
/// motion bound, the warm overlap, the cached axis (each when switched on; the first two only with the
/// cached axis, whose test they stand for). `true` when the pair is answered (`state.geometry` written, or
/// kept by the motion bound); `false` when the full query must run (then the kept separation is dropped:
/// the query may move the cached axis).
pub(super) fn polyhedron_pair(
    skips: &Skips,
    (pose_a, a): (&Pose, &ConvexPolyhedron),
    (pose_b, b): (&Pose, &ConvexPolyhedron),
    tol: &ContactTolerances,
    state: &mut ContactState,
    epa: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> bool {
    if skips.cached_axis {
        let pos12 = pose_a.inv_mul(pose_b);
        if skips.motion_bound && still_separated(&state.separation, &pos12, a, b, tol, counters) {
            // The cached-axis test would reject the pair: its last geometry stays.
            return true;
        }
        if skips.warm_overlap {
            if let Some(g) = warm_overlap_with(
                pose_a,
                &pos12,
                a,
                pose_b,
                b,
                tol,
                &mut state.cache,
                epa,
                counters,
            ) {
                state.geometry = g;
                state.separation.clear();
                return true;
            }
        }
        if let Some(g) = reject_by_cached_axis(
            pose_a,
            &pos12,
            a,
            b,
            tol,
            &mut state.cache,
            &mut state.separation,
            counters,
        ) {
            state.geometry = g;
            return true;
        }
    }
    state.separation.clear();
    false
}

/// The round-off margin of a stored separation, relative to the pair's size and distance
/// (R_A + R_B + |t₁₂|): the cached-axis test and the bound each round at ~1e-15 of that.
pub const MOTION_BOUND_MARGIN: Real = 1e-9;

/// The motion bound of a polyhedron pair with B at `pos12` in A's frame: whether the pair's cached-axis
/// test is certain to reject it, from the separation the store kept (`bound`) and the relative motion
/// since (see the module docs). Counted as a skip and a separated pair when it is.
#[inline]
pub fn still_separated(
    bound: &SeparationBound,
    pos12: &Pose,
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    tol: &ContactTolerances,
    counters: &mut QueryCounters,
) -> bool {
    if bound.gap <= 0.0 {
        return false;
    }
    let touch = tol.touching * a.length_scale().max(b.length_scale());
    let moved = (pos12.translation.vector - bound.pos12.translation.vector).norm();
    // sin(φ/2) of the rotation between the two relative orientations: the vector part of q₀⁻¹ q.
    let (q0, q) = (
        bound.pos12.rotation.quaternion(),
        pos12.rotation.quaternion(),
    );
    let (v0, v) = (q0.imag(), q.imag());
    let half_sin = (q0.w * v - q.w * v0 - v0.cross(&v)).norm();
    if moved + 2.0 * half_sin * b.bounding_radius() + touch < bound.gap {
        counters.motion_bound_skips += 1;
        counters.separated += 1;
        true
    } else {
        false
    }
}

/// The cached-axis rejection of two polyhedra, A at `pos1` and B at `pos12` in A's frame: `Some(separated)`
/// when the pair's cached GJK direction still separates them by more than the touching band (one support
/// call per shape). The cache's support hints are refreshed and its EPA face dropped (the pair no longer
/// overlaps); `bound` keeps the proof for [`still_separated`] (for shapes within the full vertex scan),
/// and is cleared when the test fails.
#[allow(clippy::too_many_arguments)]
pub fn reject_by_cached_axis(
    pos1: &Pose,
    pos12: &Pose,
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    bound: &mut SeparationBound,
    counters: &mut QueryCounters,
) -> Option<ContactGeometry> {
    if cache.dir == Vector::zeros() {
        bound.clear();
        return None;
    }
    let touch = tol.touching * a.length_scale().max(b.length_scale());
    // h_A(n) + h_B(−n) < −band along n = −v̂ proves separation (n in A's frame).
    let n = -cache.dir.normalize();
    let scan = a.vertices().len() <= SCAN_MAX_VERTICES && b.vertices().len() <= SCAN_MAX_VERTICES;
    let (s, pa, pb, ha, hb) = if scan {
        overlap_along(
            &VertexScan(a.vertex_columns()),
            &VertexScan(b.vertex_columns()),
            pos12,
            cache,
            &n,
        )
    } else {
        overlap_along(a, b, pos12, cache, &n)
    };
    if s >= -touch {
        bound.clear();
        return None;
    }
    counters.cached_axis_rejections += 1;
    counters.separated += 1;
    cache.hint_a = ha;
    cache.hint_b = hb;
    cache.has_face = false;
    // The proof kept for the motion bound: only where the incoming hints are not read (the full scan).
    let margin = MOTION_BOUND_MARGIN
        * (a.bounding_radius() + b.bounding_radius() + pos12.translation.vector.norm());
    *bound = SeparationBound {
        pos12: *pos12,
        gap: if scan { (-s - margin).max(0.0) } else { 0.0 },
    };
    let normal = pos1.rotation * n;
    // The witness points of the separation along n: the supporting points of A and B (frame 1).
    Some(separated(
        -s,
        normal,
        pos1 * Point::from(pa),
        pos1 * Point::from(pb),
    ))
}

/// h_A(n) + h_B(−n) with the support points (frame 1) and the updated hints.
fn overlap_along<SA: SupportMap + ?Sized, SB: SupportMap + ?Sized>(
    sa: &SA,
    sb: &SB,
    pos12: &Pose,
    cache: &PairCache,
    n: &Vector,
) -> (Real, Vector, Vector, u32, u32) {
    let mut pair = MinkowskiPair::new(sa, sb, pos12, cache.hint_a, cache.hint_b);
    let (s, p) = pair.overlap_along(n);
    (s, p.a, p.b, pair.hint_a, pair.hint_b)
}

/// Both shapes polyhedra: the pair the cached axis applies to.
pub fn polyhedra<'s>(
    a: &'s Shape,
    b: &'s Shape,
) -> Option<(&'s ConvexPolyhedron, &'s ConvexPolyhedron)> {
    match (a, b) {
        (Shape::Polyhedron(a), Shape::Polyhedron(b)) => Some((a.as_ref(), b.as_ref())),
        _ => None,
    }
}
