//! Plane–polyhedron contact: exact depth from the support along the plane normal, the force point at the
//! support point (the gradient point of the Minkowski overlap).
//!
//! The plane (A, a wall) is the half-space {x : n·x ≤ o}. The overlap is the exact support distance
//! δ = o − min_v n·v over the polyhedron's vertices (B), normal n (from the wall to the body).
//!
//! Contact point: δ is the maximum of the vertex depths, so its gradient with respect to the body's pose is
//! that of the deepest vertex: a force −U'(δ) n applied at the deepest vertex is exactly the generalised
//! force of the potential U(δ), which is what makes an elastic law energy-conserving (paper §2.1). c2 is
//! therefore the deepest vertex and c1 = c2 + δ n its foot on the plane (c1 − c2 = δ n exactly). When several
//! vertices are equally deep within round-off (1e-12 L: a face or an edge resting flat on the wall) the
//! point is their centroid, the symmetric element of the sub-gradient. The point jumps between vertices as
//! a flat face rocks through the tie — the kink of δ = max(d_i) is a property of the Minkowski-overlap model,
//! not of this path. (A depth-weighted centroid of all penetrating vertices varies continuously but is not
//! the gradient of any potential; it was measured to lose ~10 % of the energy of an edge landing flat,
//! `tests/polyhedral_energy_gates.rs`.)
//!
//! Status `Exact`. O(V), no allocation.

use super::contact_sphere_sphere::classify;
use super::sat::Polytope;
use super::tolerances::ContactTolerances;
use super::{ContactGeometry, SolverStatus};
use crate::math::{Point, Pose, Real, Vector};

/// Contact of the plane (A: pose `pos1`, local outward normal `normal1`, offset `offset1`) with the
/// polytope `b` at `pos2`.
pub fn contact_plane_polytope<B: Polytope + ?Sized>(
    pos1: &Pose,
    normal1: &Vector,
    offset1: Real,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
) -> ContactGeometry {
    let n = pos1.rotation * normal1;
    let o = offset1 + n.dot(&pos1.translation.vector);
    // Work in B's frame: n2 = R2ᵀ n, o2 = o − n·t2.
    let n2 = pos2.rotation.inverse_transform_vector(&n);
    let o2 = o - n.dot(&pos2.translation.vector);
    let verts = b.vertices();
    let lowest = verts
        .iter()
        .map(|v| n2.dot(&v.coords))
        .fold(Real::INFINITY, Real::min);
    let signed = o2 - lowest;
    let touch = tol.touching * b.length_scale();
    let (kind, depth, distance) = classify(signed, touch);
    // The deepest vertex, or the centroid of the vertices tied with it within round-off.
    let tie = 1e-12 * b.length_scale();
    let (mut sum, mut count) = (Vector::zeros(), 0.0);
    for v in verts {
        if n2.dot(&v.coords) <= lowest + tie {
            sum += v.coords;
            count += 1.0;
        }
    }
    let xbar = sum / count;
    let c2_local = xbar - n2 * (n2.dot(&xbar) - lowest);
    let point_b = pos2 * Point::from(c2_local);
    let point_a = point_b + n * signed;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::testing::{random_rotation, TestPolytope};
    use crate::contact::ContactKind;
    use rand::{Rng, SeedableRng};

    #[test]
    fn box_resting_on_a_wall_reports_its_face_centroid() {
        let tol = ContactTolerances::default();
        let h = Vector::new(1.0, 0.5, 0.25);
        let bx = TestPolytope::cuboid(h);
        for scale in [1e-3, 1.0, 1e3] {
            let bxs = TestPolytope::cuboid(h * scale);
            let pos2 = Pose::translation(2.0 * scale, -scale, (0.25 - 1e-7) * scale);
            let g = contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, &pos2, &bxs, &tol);
            assert_eq!(g.kind, ContactKind::Overlap, "{g:?}");
            assert!(
                (g.depth - 1e-7 * scale).abs() <= 1e-15 * scale,
                "depth {} scale {scale}",
                g.depth
            );
            let want = Point::new(2.0 * scale, -scale, 0.0);
            assert!(
                (g.point_a - want).norm() <= 1e-14 * scale,
                "c1 {:?} want {want:?}",
                g.point_a
            );
            assert!((g.point_a - g.point_b - g.normal * g.depth).norm() <= 1e-15 * scale);
        }
        let _ = bx;
    }

    /// The torque of the contact force about the body's centre is the gradient of δ with respect to the
    /// body's rotation: d δ / d θ (about axis e) = −((c2 − x_B) × n)·e, checked by central differences on
    /// random tilted poses. This is what makes an elastic law energy-conserving.
    #[test]
    fn contact_point_is_the_gradient_point_of_the_overlap() {
        let tol = ContactTolerances::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let bx = TestPolytope::cuboid(Vector::new(1.0, 0.5, 0.25));
        let depth_at = |pos2: &Pose| {
            let lowest = bx
                .verts
                .iter()
                .map(|v| (pos2 * v).z)
                .fold(Real::INFINITY, Real::min);
            -lowest
        };
        for k in 0..200 {
            // Half random orientations (one vertex below the wall), half nearly flat (a face tilted by
            // ~1e-3 rad: several vertices below, one deepest).
            let rot = if k % 2 == 0 {
                random_rotation(&mut rng)
            } else {
                let axis = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                );
                crate::math::Rotation::from_scaled_axis(axis * 1e-3)
            };
            let low = bx
                .verts
                .iter()
                .map(|v| (rot * v).z)
                .fold(Real::INFINITY, Real::min);
            let pos2 = Pose::from_parts(Vector::new(0.3, -0.2, -low - 1e-3).into(), rot);
            let g = contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, &pos2, &bx, &tol);
            assert_eq!(g.kind, ContactKind::Overlap);
            let arm = g.point_b - Point::from(pos2.translation.vector);
            for e in [Vector::x(), Vector::y(), Vector::z()] {
                let h = 1e-7;
                let turn = |s: Real| {
                    let r = crate::math::Rotation::from_scaled_axis(e * s);
                    Pose::from_parts(pos2.translation, r * pos2.rotation)
                };
                let fd = (depth_at(&turn(h)) - depth_at(&turn(-h))) / (2.0 * h);
                let want = -arm.cross(&g.normal).dot(&e);
                assert!(
                    (fd - want).abs() < 1e-6,
                    "axis {e:?}: dδ/dθ = {fd}, torque arm gives {want}"
                );
            }
        }
    }

    #[test]
    fn depth_is_the_support_distance_for_random_poses() {
        let tol = ContactTolerances::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let bx = TestPolytope::cuboid(Vector::new(1.0, 0.7, 0.3));
        let wall = Pose::from_parts(
            Vector::new(0.1, 0.2, -0.3).into(),
            random_rotation(&mut rng),
        );
        for _ in 0..200 {
            let rot = random_rotation(&mut rng);
            let pos2 = Pose::from_parts((wall * Point::new(0.0, 0.0, 0.5)).coords.into(), rot);
            let g = contact_plane_polytope(&wall, &Vector::z(), 0.0, &pos2, &bx, &tol);
            let n = wall.rotation * Vector::z();
            let o = n.dot(&wall.translation.vector);
            let lowest = bx
                .verts
                .iter()
                .map(|v| n.dot(&(pos2 * v).coords))
                .fold(Real::INFINITY, Real::min);
            let want = o - lowest;
            let got = if g.kind == ContactKind::Overlap {
                g.depth
            } else {
                -g.distance
            };
            assert!((got - want).abs() <= 1e-14, "depth {got} want {want}");
            assert!(
                (n.dot(&g.point_a.coords) - o).abs() <= 1e-14,
                "c1 off the wall"
            );
        }
    }
}
