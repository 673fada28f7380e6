//! Bounded convex shape – plane (wall) contact in closed form: the support point of the shape along −n is
//! its deepest point, so the signed overlap is exact, s = o − n·s_B(−n) for the wall's plane n·x = o.
//!
//! This serves every shape with a support map that has no special wall path (ellipsoids); polyhedra keep
//! their own path ([`super::contact_polyhedron_plane`]), which smooths the depth for the law.

use super::contact_sphere_sphere::classify;
use super::tolerances::ContactTolerances;
use super::{ContactGeometry, SolverStatus};
use crate::math::{Pose, Real, Vector};
use crate::shape::ConvexShape;

/// Contact of the wall `n·x ≤ offset1` (local normal `normal1`, unit) at `pos1` with the shape `b` at `pos2`:
/// normal `n` from the wall (A) to the shape (B), c2 the shape's deepest point, c1 its projection on the
/// wall's plane, so that c1 − c2 = s n.
pub fn contact_plane_convex<B: ConvexShape + ?Sized>(
    pos1: &Pose,
    normal1: &Vector,
    offset1: Real,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
) -> ContactGeometry {
    let n = pos1.rotation * normal1;
    let o = offset1 + n.dot(&pos1.translation.vector);
    let deepest_local = b.local_support(&(pos2.rotation.inverse() * -n), &mut 0);
    let point_b = pos2 * deepest_local;
    let signed = o - n.dot(&point_b.coords);
    let point_a = point_b + n * signed;
    let (kind, depth, distance) = classify(signed, tol.touching * b.length_scale());
    ContactGeometry::from_points(
        kind,
        depth,
        distance,
        n,
        point_a,
        point_b,
        SolverStatus::Exact,
    )
}
