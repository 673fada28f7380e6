//! Plane–sphere contact, in closed form.
//!
//! The plane (wall) is the half-space {x : n·x ≤ o} of its local frame, with `n` the outward unit normal
//! and `o` the offset. With s = n·c − o the signed height of the sphere's centre c: δ = r − s, normal n
//! (from the wall to the sphere), c1 = c − s n (foot of the centre on the plane), c2 = c − r n (deepest point
//! of the sphere), so c1 − c2 = δ n. The length scale of the pair is the sphere's diameter.

use super::contact_sphere_sphere::classify;
use super::tolerances::ContactTolerances;
use super::{ContactGeometry, SolverStatus};
use crate::math::{Point, Pose, Real, Vector};

/// Contact of the plane (A: pose `pos1`, local outward normal `normal1`, offset `offset1`) with the sphere
/// (B: centre `c2` in world, radius `r2`).
pub fn contact_plane_sphere(
    pos1: &Pose,
    normal1: &Vector,
    offset1: Real,
    c2: &Point,
    r2: Real,
    tol: &ContactTolerances,
) -> ContactGeometry {
    let n = pos1.rotation * normal1;
    let o = offset1 + n.dot(&pos1.translation.vector);
    let height = n.dot(&c2.coords) - o;
    let (point_a, point_b) = plane_sphere_points(c2, r2, &n, height);
    let (kind, depth, distance) = classify(r2 - height, tol.touching * 2.0 * r2);
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

/// The witness points of a sphere (centre `c2`, radius `r2`) against a plane of unit normal `n` (world)
/// whose centre is at the signed height `height` above it: the foot c₂ − h n on the plane and the deepest
/// point c₂ − r₂ n of the sphere. Shared by [`contact_plane_sphere`] and the flat sphere layout's wall
/// pairs (which keep n and the plane's offset per wall).
#[inline(always)]
pub fn plane_sphere_points(c2: &Point, r2: Real, n: &Vector, height: Real) -> (Point, Point) {
    (c2 - n * height, c2 - n * r2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactKind;

    #[test]
    fn sphere_on_tilted_wall() {
        let tol = ContactTolerances::default();
        let rot = crate::math::Rotation::from_euler_angles(0.4, -0.2, 0.9);
        let wall = Pose::from_parts(Vector::new(1.0, 2.0, 3.0).into(), rot);
        for scale in [1e-3, 1.0, 1e3] {
            let r = 0.5 * scale;
            let n = rot * Vector::z();
            let c = wall * Point::new(0.3 * scale, -0.2 * scale, 0.0) + n * (r - 1e-6 * scale);
            let g = contact_plane_sphere(&wall, &Vector::z(), 0.0, &c, r, &tol);
            assert_eq!(g.kind, ContactKind::Overlap, "{g:?}");
            let coord = scale + c.coords.norm();
            assert!(
                (g.depth - 1e-6 * scale).abs() <= 1e-14 * coord,
                "depth {} scale {scale}",
                g.depth
            );
            assert!((g.normal - n).norm() < 1e-15);
            let on_plane = n.dot(&(g.point_a - wall.translation.vector).coords);
            assert!(
                on_plane.abs() <= 1e-14 * scale.max(3.0),
                "c1 off the plane by {on_plane}"
            );
            // Round-off is relative to the coordinates (the wall sits at |t| ≈ 3.7), not to the sphere.
            let coord = scale + c.coords.norm();
            let off = ((g.point_b - c).norm() - r).abs();
            assert!(
                off <= 1e-14 * coord,
                "c2 off the sphere by {off:e} (scale {scale})"
            );
        }
    }
}
