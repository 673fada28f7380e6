//! Polyhedron–sphere contact: GJK distance from the polyhedron to the sphere's centre, or the exact depth of
//! a centre inside the polyhedron.
//!
//! With c the sphere's centre (radius r) in the polyhedron's frame (A):
//! - c outside A: GJK between A and the point c gives the exact distance d, the closest point q on A and
//!   the normal n = (c − q)/d (from the polyhedron's terminal feature, accurate for small d); δ = r − d,
//!   c1 = q, c2 = c − r n;
//! - c inside A or within the touching band of its surface: the depth of a point in a convex polytope is
//!   exactly min_f (o_f − n_f·c) over the face planes (no EPA needed), with the arg-min face's normal n;
//!   δ = r + that depth, c1 = c + depth·n on the face, c2 = c − r n.
//!
//! Either way c1 − c2 = δ n, c1 on the polyhedron and c2 on the sphere. A GJK iteration cap falls back to
//! the exact closest point by exhaustion over the face triangles (status `FallbackAfterMaxIterations`).

use super::contact_sphere_sphere::classify;
use super::counters::QueryCounters;
use super::features::closest_on_triangle;
use super::gjk::{gjk, GjkMode, GjkOutcome, Simplex};
use super::minkowski::MinkowskiPair;
use super::sat::Polytope;
use super::tolerances::{pair_length_scale, ContactTolerances};
use super::{ContactGeometry, SolverStatus};
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::SupportMap;

/// A single point as a support map (its own support in every direction).
struct PointShape(Point);

impl SupportMap for PointShape {
    fn local_support(&self, _dir: &Vector, _hint: &mut u32) -> Point {
        self.0
    }
}

/// Contact of the polytope `a` at `pos1` with the sphere of centre `c2` (world) and radius `r2`.
pub fn contact_polytope_sphere<A: Polytope + ?Sized>(
    pos1: &Pose,
    a: &A,
    c2: &Point,
    r2: Real,
    tol: &ContactTolerances,
    hint: &mut u32,
    counters: &mut QueryCounters,
) -> ContactGeometry {
    counters.sphere_polyhedron += 1;
    let scale = pair_length_scale(a.length_scale(), 2.0 * r2);
    let touch = tol.touching * scale;
    let c = pos1.inverse_transform_point(c2);
    let origin = PointShape(Point::origin());
    let pos12 = Pose::translation(c.x, c.y, c.z);
    let mut pair = MinkowskiPair::new(a, &origin, &pos12, *hint, 0);
    let mut simplex = Simplex::default();
    let gr = gjk(
        &mut pair,
        &(-c.coords),
        scale,
        tol,
        GjkMode::Distance,
        &mut simplex,
    );
    *hint = pair.hint_a;
    counters.gjk_runs += 1;
    counters.gjk_iterations += gr.iterations as u64;
    let (signed, n, c1, status) = match gr.outcome {
        GjkOutcome::Separated {
            distance,
            normal,
            point_a,
            ..
        } => (r2 - distance, normal, point_a, SolverStatus::Converged),
        GjkOutcome::Contact => {
            // Centre inside (or on) A: the nearest face plane.
            let (mut best, mut best_f) = (Real::INFINITY, 0);
            for f in 0..a.num_faces() {
                let depth = a.face_offset(f) - a.face_normal(f).dot(&c.coords);
                if depth < best {
                    best = depth;
                    best_f = f;
                }
            }
            let n = a.face_normal(best_f);
            (r2 + best, n, c.coords + n * best, SolverStatus::Converged)
        }
        GjkOutcome::MaxIterations | GjkOutcome::SeparatingAxis => {
            let (q, d) = closest_point_on_polytope(a, &c.coords);
            let n = if d > 0.0 {
                (c.coords - q) / d
            } else {
                Vector::x()
            };
            (r2 - d, n, q, SolverStatus::FallbackAfterMaxIterations)
        }
    };
    let (kind, depth, distance) = classify(signed, touch);
    let point_a = pos1 * Point::from(c1);
    let normal = pos1.rotation * n;
    let point_b = c2 - normal * r2;
    let g = ContactGeometry::from_points(kind, depth, distance, normal, point_a, point_b, status);
    counters.record(&g);
    g
}

/// Exact closest point of a polytope's surface to an outside point `p` (local frame), by exhaustion over the
/// face triangles: (point, distance).
fn closest_point_on_polytope<A: Polytope + ?Sized>(a: &A, p: &Vector) -> (Vector, Real) {
    let v = a.vertices();
    let mut best = (v[0].coords, Real::INFINITY);
    for f in 0..a.num_faces() {
        let fv = a.face_vertices(f);
        for k in 1..fv.len().saturating_sub(1) {
            let q = closest_on_triangle(
                p,
                &v[fv[0] as usize].coords,
                &v[fv[k] as usize].coords,
                &v[fv[k + 1] as usize].coords,
            );
            let d = (q - p).norm();
            if d < best.1 {
                best = (q, d);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::testing::{random_pose, random_unit, TestPolytope};
    use crate::contact::ContactKind;
    use rand::{Rng, SeedableRng};

    /// Exact signed overlap of a sphere with a polytope (local frame): r − distance outside, r + depth inside.
    fn exact(a: &TestPolytope, c: &Vector, r: Real) -> Real {
        let inside = (0..a.num_faces())
            .map(|f| a.face_offset(f) - a.face_normal(f).dot(c))
            .fold(Real::INFINITY, Real::min);
        if inside >= 0.0 {
            r + inside
        } else {
            r - closest_point_on_polytope(a, c).1
        }
    }

    #[test]
    fn sphere_polyhedron_matches_exact_distance_and_depth() {
        let tol = ContactTolerances::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
        let mut counters = QueryCounters::default();
        for scale in [1e-3, 1.0, 1e3] {
            let a = TestPolytope::cuboid(Vector::new(1.0, 0.6, 0.4) * scale);
            for i in 0..2000 {
                let pos1 = random_pose(&mut rng, scale);
                let r = rng.random_range(0.1..1.0) * scale;
                let dir = random_unit(&mut rng);
                let dist = rng.random_range(0.0..2.5) * scale;
                let c_local = dir * dist;
                let c2 = pos1 * Point::from(c_local);
                let mut hint = 0;
                let g = contact_polytope_sphere(&pos1, &a, &c2, r, &tol, &mut hint, &mut counters);
                let want = exact(&a, &c_local, r);
                let got = match g.kind {
                    ContactKind::Overlap => g.depth,
                    ContactKind::Separated => -g.distance,
                    ContactKind::Touching => 0.0,
                };
                let allowed = 1e-10 * scale + 1e-9 * want.abs();
                assert!(
                    (got - want).abs() <= allowed,
                    "pair {i} scale {scale}: centre {c_local:?} r {r}: got {got:e}, exact {want:e}, tol {allowed:e}"
                );
                let diff = (g.point_a - g.point_b) - g.normal * got;
                assert!(
                    diff.norm() <= 1e-12 * scale,
                    "pair {i}: c1 − c2 − δ n = {diff:?}"
                );
                assert!(
                    ((g.point_b - c2).norm() - r).abs() <= 1e-12 * scale,
                    "c2 off the sphere"
                );
            }
        }
        assert_eq!(counters.fallbacks(), 0, "{counters}");
    }
}
