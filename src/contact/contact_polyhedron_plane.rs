//! Plane–polyhedron contact: exact depth from the support along the plane normal, and a contact point that
//! moves continuously with the pose.
//!
//! The plane (A, a wall) is the half-space {x : n·x ≤ o}. The overlap is the exact support distance
//! δ = o − min_v n·v over the polyhedron's vertices (B), normal n (from the wall to the body).
//!
//! Contact point: the deepest vertex alone would jump from corner to corner as a face rocks on the wall, and
//! a force law would see a discontinuous lever arm. Here the lateral position is the centroid of the
//! vertices below the plane weighted by their penetration depths, x̄ = Σ w_i v_i / Σ w_i with
//! w_i = max(0, o − n·v_i): it is continuous in the pose (weights vanish continuously as vertices leave), it
//! is the centroid of a face resting flat on the wall, and it is the deepest vertex when only that one is
//! below. c2 is x̄ moved along n onto the deepest level (n·c2 = min n·v) and c1 = c2 + δ n lies on the plane,
//! so c1 − c2 = δ n exactly. c2 lies on the body's surface whenever the penetrating vertices belong to the
//! deepest feature (a vertex, or an edge or face parallel to the wall); for a tilted face it lies at most δ
//! below the surface, inside the body — the price of continuity.
//!
//! Touching or separated pairs report the plain centroid of the vertices within the touching band of the
//! deepest level (continuous where it matters: no force acts there). Status `Exact`. O(V), no allocation.

use super::contact_sphere_sphere::classify;
use super::sat::Polytope;
use super::tolerances::ContactTolerances;
use super::{ContactGeometry, ContactKind, SolverStatus};
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
    let (mut sum, mut wsum) = (Vector::zeros(), 0.0);
    if kind == ContactKind::Overlap {
        for v in verts {
            let w = o2 - n2.dot(&v.coords);
            if w > 0.0 {
                sum += v.coords * w;
                wsum += w;
            }
        }
    } else {
        for v in verts {
            if n2.dot(&v.coords) <= lowest + touch {
                sum += v.coords;
                wsum += 1.0;
            }
        }
    }
    let xbar = sum / wsum;
    let c2_local = xbar - n2 * (n2.dot(&xbar) - lowest);
    let point_b = pos2 * Point::from(c2_local);
    let point_a = point_b + n * signed;
    ContactGeometry {
        kind,
        depth,
        distance,
        normal: n,
        point_a,
        point_b,
        point: nalgebra::center(&point_a, &point_b),
        status: SolverStatus::Exact,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::testing::{random_rotation, TestPolytope};
    use rand::SeedableRng;

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

    #[test]
    fn contact_point_moves_continuously_as_a_face_tilts() {
        // Rock a box about the y axis through the flat position: the contact point must not jump.
        let tol = ContactTolerances::default();
        let bx = TestPolytope::cuboid(Vector::new(1.0, 0.5, 0.25));
        let mut prev: Option<Point> = None;
        let steps = 2001;
        for k in 0..steps {
            let angle = 1e-3 * (2.0 * k as Real / (steps - 1) as Real - 1.0);
            let rot = crate::math::Rotation::from_euler_angles(0.0, angle, 0.0);
            // Keep the depth of the lowest vertex at 1e-4.
            let low = bx
                .verts
                .iter()
                .map(|v| (rot * v).z)
                .fold(Real::INFINITY, Real::min);
            let pos2 = Pose::from_parts(Vector::new(0.0, 0.0, -low - 1e-4).into(), rot);
            let g = contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, &pos2, &bx, &tol);
            assert_eq!(g.kind, ContactKind::Overlap);
            if let Some(p) = prev {
                let jump = (g.point - p).norm();
                // A deepest-vertex point would jump by the face length (2) at the flat position.
                assert!(
                    jump < 0.1,
                    "step {k}, angle {angle:e}: contact point jumped by {jump}"
                );
            }
            prev = Some(g.point);
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
