//! Dispatch of a contact query over the shape kinds: one fast path per pair of kinds, the order of the pair
//! kept (A, B) by swapping the answer of the mirrored path when needed.
//!
//! | A \ B       | Polyhedron                     | Sphere                         | Plane            |
//! |-------------|--------------------------------|--------------------------------|------------------|
//! | Polyhedron  | GJK + EPA (+ SAT fallback)     | GJK to the centre / face scan  | support along n  |
//! | Sphere      | mirrored                       | closed form                    | closed form      |
//! | Plane       | support along n                | closed form                    | error            |
//!
//! Any other pair of bounded shapes (an ellipsoid with anything) goes through the generic support-map arm
//! ([`super::contact_support_map`]: GJK + EPA stopped by `curved_gap`), and against a plane through the
//! closed form of [`super::contact_convex_plane`]. A new shape reaches both through
//! [`Shape::convex`](crate::shape::Shape::convex) without an edit here.
//!
//! Every path returns the same [`ContactGeometry`] features (δ_M, n_M from A to B, c1 on A, c2 on B,
//! c_M), so a contact law never needs to know which path ran. Two walls never collide: a plane–plane
//! query is a typed error, not a panic.

use super::contact_convex_plane::contact_plane_convex;
use super::contact_polyhedron_plane::contact_plane_polytope;
use super::contact_polyhedron_polyhedron::{
    query_polytopes_cached, warm_overlap_polytopes, PairCache,
};
use super::contact_sphere_plane::contact_plane_sphere;
use super::contact_sphere_polyhedron::contact_polytope_sphere;
use super::contact_sphere_sphere::contact_sphere_sphere;
use super::contact_support_map::contact_support_maps;
use super::counters::QueryCounters;
use super::epa::EpaScratch;
use super::pair_smoothing::{smooth_pair_overlap, PairSmoothing};
use super::tolerances::ContactTolerances;
use super::{ContactGeometry, ContactKind};
use crate::math::{Point, Pose};
use crate::shape::{ConvexPolyhedron, ConvexShape, Plane, Shape};

/// A query that has no meaning.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ContactError {
    /// Both shapes are planes: walls never touch each other.
    #[error("contact between two planes (walls) is not defined")]
    PlanePlane,
}

/// The same contact seen from the other side: (A, B) ↦ (B, A).
pub fn swap_pair(g: &ContactGeometry) -> ContactGeometry {
    ContactGeometry {
        normal: -g.normal,
        point_a: g.point_b,
        point_b: g.point_a,
        ..*g
    }
}

/// Contact query between any two shapes with the default tolerances (hot path: the caller keeps one
/// [`PairCache`] per pair, one [`EpaScratch`] and one [`QueryCounters`] per thread).
pub fn query(
    pos1: &Pose,
    shape1: &Shape,
    pos2: &Pose,
    shape2: &Shape,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> Result<ContactGeometry, ContactError> {
    query_with(
        pos1,
        shape1,
        pos2,
        shape2,
        &ContactTolerances::default(),
        cache,
        scratch,
        counters,
    )
}

/// [`query`] with explicit tolerances.
#[allow(clippy::too_many_arguments)]
pub fn query_with(
    pos1: &Pose,
    shape1: &Shape,
    pos2: &Pose,
    shape2: &Shape,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> Result<ContactGeometry, ContactError> {
    let centre = |pos: &Pose| Point::from(pos.translation.vector);
    let g = match (shape1, shape2) {
        (Shape::Polyhedron(a), Shape::Polyhedron(b)) => {
            let g = query_polytopes_cached(
                pos1,
                a.as_ref(),
                pos2,
                b.as_ref(),
                tol,
                cache,
                scratch,
                counters,
            );
            law_overlap(pos1, a.as_ref(), pos2, b.as_ref(), tol, cache, g)
        }
        (Shape::Polyhedron(a), Shape::Sphere(s)) => contact_polytope_sphere(
            pos1,
            a.as_ref(),
            &centre(pos2),
            s.radius(),
            tol,
            &mut cache.hint_a,
            counters,
        ),
        (Shape::Sphere(s), Shape::Polyhedron(b)) => swap_pair(&contact_polytope_sphere(
            pos2,
            b.as_ref(),
            &centre(pos1),
            s.radius(),
            tol,
            &mut cache.hint_b,
            counters,
        )),
        (Shape::Sphere(s1), Shape::Sphere(s2)) => {
            counters.sphere_sphere += 1;
            let g =
                contact_sphere_sphere(&centre(pos1), s1.radius(), &centre(pos2), s2.radius(), tol);
            counters.record(&g);
            g
        }
        (Shape::Plane(_), Shape::Plane(_)) => return Err(ContactError::PlanePlane),
        (Shape::Plane(p), other) => plane_contact(pos1, p, pos2, other, tol, counters)?,
        (other, Shape::Plane(p)) => swap_pair(&plane_contact(pos2, p, pos1, other, tol, counters)?),
        (a, b) => {
            let (a, b) = (bounded(a)?, bounded(b)?);
            contact_support_maps(pos1, a, pos2, b, tol, cache, scratch, counters).geometry
        }
    };
    Ok(g)
}

/// The contact of the wall `plane` at `pos_plane` (A) with the solid `other` at `pos_other` (B), counted:
/// the closed forms for a sphere and a polyhedron, the convex–plane form for any other solid.
fn plane_contact(
    pos_plane: &Pose,
    plane: &Plane,
    pos_other: &Pose,
    other: &Shape,
    tol: &ContactTolerances,
    counters: &mut QueryCounters,
) -> Result<ContactGeometry, ContactError> {
    let (normal, offset) = (plane.normal(), plane.offset());
    let g = match other {
        Shape::Sphere(s) => {
            counters.sphere_plane += 1;
            let centre = Point::from(pos_other.translation.vector);
            contact_plane_sphere(pos_plane, normal, offset, &centre, s.radius(), tol)
        }
        Shape::Polyhedron(b) => {
            counters.polyhedron_plane += 1;
            contact_plane_polytope(pos_plane, normal, offset, pos_other, b.as_ref(), tol)
        }
        other => {
            counters.convex_plane += 1;
            contact_plane_convex(pos_plane, normal, offset, pos_other, bounded(other)?, tol)
        }
    };
    counters.record(&g);
    Ok(g)
}

/// The shape as a bounded convex solid; a plane here can only be the second of two walls.
fn bounded(shape: &Shape) -> Result<&dyn ConvexShape, ContactError> {
    shape.convex().ok_or(ContactError::PlanePlane)
}

/// The overlap of a polyhedron pair handed to the law, from the exact geometry `g` of its query (the
/// cache as the query left it): smoothed per `tol.pair_smoothing` ([`super::pair_smoothing`]).
fn law_overlap(
    pos1: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
    tol: &ContactTolerances,
    cache: &PairCache,
    g: ContactGeometry,
) -> ContactGeometry {
    match tol.pair_smoothing {
        PairSmoothing::Smoothed { band } if g.kind == ContactKind::Overlap => {
            smooth_pair_overlap(pos1, a, pos2, b, &g, band, [cache.hint_a, cache.hint_b])
        }
        _ => g,
    }
}

/// The polyhedron–polyhedron case of [`query_with`] (B at `pos12` in A's frame, as `pos1.inv_mul(pos2)`
/// gives it) when the pair's warm start proves the overlap ([`warm_overlap_polytopes`]): `Some` with what
/// [`query_with`] returns, pair smoothing included, and the same cache and counters; `None` with nothing
/// changed otherwise.
#[allow(clippy::too_many_arguments)]
pub fn warm_overlap_with(
    pos1: &Pose,
    pos12: &Pose,
    a: &ConvexPolyhedron,
    pos2: &Pose,
    b: &ConvexPolyhedron,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> Option<ContactGeometry> {
    let g = warm_overlap_polytopes(pos1, pos12, a, b, tol, cache, scratch, counters)?;
    Some(law_overlap(pos1, a, pos2, b, tol, cache, g))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ContactKind, SolverStatus};
    use crate::math::{Real, Rotation, Vector};
    use crate::shape::{ConvexPolyhedron, Plane, Sphere};
    use std::sync::Arc;

    fn cube(h: Real) -> Shape {
        let pts: Vec<Point> = (0..8)
            .map(|i| {
                let s = |b: usize| if i & (1 << b) != 0 { h } else { -h };
                Point::new(s(0), s(1), s(2))
            })
            .collect();
        Shape::Polyhedron(Arc::new(
            ConvexPolyhedron::from_points(&pts).expect("cube").0,
        ))
    }

    /// Every path, in both orders, gives the mirrored answer of the other order and obeys c1 − c2 = δ n.
    #[test]
    fn both_orders_agree_on_every_path() {
        let shapes = [
            (cube(0.5), "cube"),
            (Shape::Sphere(Sphere::new(0.4).expect("sphere")), "sphere"),
            (
                Shape::Plane(Plane::new(Vector::z(), 0.0).expect("plane")),
                "plane",
            ),
        ];
        let pos1 = Pose::from_parts(
            Vector::new(0.1, -0.2, 0.05).into(),
            Rotation::from_euler_angles(0.1, 0.2, 0.3),
        );
        let pos2 = Pose::from_parts(
            Vector::new(0.3, 0.1, 0.3).into(),
            Rotation::from_euler_angles(-0.3, 0.5, 0.2),
        );
        let mut scratch = EpaScratch::default();
        let mut counters = QueryCounters::default();
        for (s1, n1) in &shapes {
            for (s2, n2) in &shapes {
                let ab = query(
                    &pos1,
                    s1,
                    &pos2,
                    s2,
                    &mut PairCache::default(),
                    &mut scratch,
                    &mut counters,
                );
                let ba = query(
                    &pos2,
                    s2,
                    &pos1,
                    s1,
                    &mut PairCache::default(),
                    &mut scratch,
                    &mut counters,
                );
                if matches!((s1, s2), (Shape::Plane(_), Shape::Plane(_))) {
                    assert_eq!(ab, Err(ContactError::PlanePlane));
                    continue;
                }
                let (ab, ba) = (ab.expect("defined"), ba.expect("defined"));
                assert_eq!(ab.kind, ContactKind::Overlap, "{n1}-{n2}: {ab:?}");
                assert_ne!(ab.status, SolverStatus::FallbackAfterDegenerate);
                assert!(
                    (ab.depth - ba.depth).abs() < 1e-12,
                    "{n1}-{n2}: depths {} vs {}",
                    ab.depth,
                    ba.depth
                );
                assert!(
                    (ab.normal + ba.normal).norm() < 1e-9,
                    "{n1}-{n2}: normals {:?} vs {:?}",
                    ab.normal,
                    ba.normal
                );
                let diff = (ab.point_a - ab.point_b) - ab.normal * ab.depth;
                assert!(diff.norm() < 1e-12, "{n1}-{n2}: c1 − c2 − δ n = {diff:?}");
            }
        }
        assert_eq!(counters.fallbacks(), 0, "{counters}");
    }
}
