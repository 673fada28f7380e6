//! Work the step skips because the scene does not need it, each switchable so that a benchmark can measure
//! it and a test can compare on against off (`tests/world_skips.rs`, `benches/step.rs`).
//!
//! | switch | what is skipped | equivalence with the switch off |
//! |---|---|---|
//! | `bounding_spheres` | the query of a body pair whose bounding spheres are apart by more than the touching band, and of a body–wall pair whose bounding sphere does not reach the plane | same forces; the pair's GJK warm start is not refreshed, so later EPA answers of that pair may differ at the solver tolerance |
//! | `cached_axis` | GJK for a polyhedron pair still separated along its cached separating direction (one support call per shape) | as above |
//! | `verlet_skin` | broad-phase rebuilds while no body moved half the skin since the last one | exact: the pair list only differs by pairs whose bounding spheres are farther apart than the skin |
//! | `frictionless_history` | the tangential spring of pairs with μ = 0 (its force is zero: the Coulomb cap is 0) | bit-identical bodies and forces (up to the sign of zero); the stored history stays empty |
//! | `undamped_contacts` | the damping term of a viscous law whose coefficient is 0 (e = 1); e = 1 already maps to `DampingLaw::None`, which costs nothing | bit-identical (up to the sign of zero) |
//! | `still_rotation` | the rotation drift of a dynamic body whose angular momentum is exactly zero | to the round-off of one quaternion renormalisation (≤ 2⁻⁵² relative) per step |
//! | `isotropic_rotation` | the five sub-rotations of the splitting for a body whose principal moments are exactly equal (a sphere): its free rotation is one turn about the constant L by the angle Δt|L|/J, done as one quaternion product, and ω = L/J without the two frame changes | not bit-identical: the splitting is only second order for such a body (its sub-flows do not commute), the single turn is its exact flow (in the Cayley form, the same modified angle 4 atan(θ/4) as the paper's sub-steps); ω differs at round-off. Bounded in `tests/world_isotropic.rs` |
//! | `sphere_kernel` | the general pair dispatch for candidates whose sides are spheres or a wall and a sphere: per-body inputs gathered once per step, the closed forms and the law called directly (`src/world/sphere_kernel.rs`); in a world of free spheres, also the per-body tests of the integration (`src/world/sphere_step.rs`) | exact: the same operations in the same order, bit-identical bodies, loads, ledger and contact store |
//! | `non_dynamic_pairs` | queries between two non-dynamic bodies (fixed or prescribed) and the integration of fixed bodies | forces between two non-dynamic bodies are not computed: they act on nothing that moves, but the force reported on such a body omits them |
//!
//! Rejected pairs are stored as `Separated` with `distance` a lower bound of the true gap (the gap of the
//! bounding spheres, or the separation along the cached axis) and witness points on that bound, not the
//! exact closest points; no later stage reads them.

use crate::contact::contact_polyhedron_polyhedron::SCAN_MAX_VERTICES;
use crate::contact::minkowski::{MinkowskiPair, VertexScan};
use crate::contact::{
    ContactGeometry, ContactKind, ContactTolerances, PairCache, QueryCounters, SolverStatus,
};
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::{ConvexPolyhedron, Shape, SupportMap};

/// The switches of the step's skips (see the module docs); all on by default: each is exact or changes
/// nothing beyond the solver tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Skips {
    pub bounding_spheres: bool,
    pub cached_axis: bool,
    pub verlet_skin: bool,
    pub frictionless_history: bool,
    pub undamped_contacts: bool,
    pub still_rotation: bool,
    pub isotropic_rotation: bool,
    pub non_dynamic_pairs: bool,
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

/// The cached-axis rejection of two polyhedra at `pos1`, `pos2`: `Some(separated)` when the pair's cached
/// GJK direction still separates them by more than the touching band (one support call per shape). The
/// cache's support hints are refreshed and its EPA face dropped (the pair no longer overlaps).
pub fn reject_by_cached_axis(
    pos1: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    counters: &mut QueryCounters,
) -> Option<ContactGeometry> {
    if cache.dir == Vector::zeros() {
        return None;
    }
    let pos12 = pos1.inv_mul(pos2);
    let touch = tol.touching * a.length_scale().max(b.length_scale());
    // h_A(n) + h_B(−n) < −band along n = −v̂ proves separation (n in A's frame).
    let n = -cache.dir.normalize();
    let (s, pa, pb, ha, hb) =
        if a.vertices().len() <= SCAN_MAX_VERTICES && b.vertices().len() <= SCAN_MAX_VERTICES {
            overlap_along(
                &VertexScan(a.vertices()),
                &VertexScan(b.vertices()),
                &pos12,
                cache,
                &n,
            )
        } else {
            overlap_along(a, b, &pos12, cache, &n)
        };
    if s >= -touch {
        return None;
    }
    counters.cached_axis_rejections += 1;
    counters.separated += 1;
    cache.hint_a = ha;
    cache.hint_b = hb;
    cache.has_face = false;
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
