//! Tests of the generic support-map arm and the convex–plane closed form with ellipsoids: the closed form
//! against the generic path, both orders of every pair kind through the dispatcher, and the explicit
//! status, bounds and count of a query that does not converge.

use super::contact_support_map::contact_support_maps;
use super::{query, query_with, ContactKind, ContactTolerances, EpaScratch, PairCache};
use super::{QueryCounters, SolverStatus};
use crate::math::{Point, Pose, Real, Rotation, Vector};
use crate::shape::{ConvexPolyhedron, Plane, Shape, Sphere};
use std::sync::Arc;

fn cuboid(half: Vector) -> ConvexPolyhedron {
    let pts: Vec<Point> = (0..8)
        .map(|i| {
            let s = |b: usize| if i & (1 << b) != 0 { half[b] } else { -half[b] };
            Point::new(s(0), s(1), s(2))
        })
        .collect();
    ConvexPolyhedron::from_points(&pts).expect("cuboid").0
}

fn tilted(x: Vector, angles: (Real, Real, Real)) -> Pose {
    Pose::from_parts(
        x.into(),
        Rotation::from_euler_angles(angles.0, angles.1, angles.2),
    )
}

/// The closed form against a wall equals the generic GJK/EPA path against a slab whose top face is the
/// wall's plane (the slab 400 ℓ wide, so that its edges are far from the contact), within the generic
/// path's tolerance curved_gap·ℓ plus the round-off of the slab's coordinates (1e-15 × 400 ℓ).
#[test]
fn convex_plane_closed_form_matches_the_generic_path() {
    let tol = ContactTolerances::default();
    let e = Shape::ellipsoid(0.3, 0.12, 0.05).expect("ellipsoid");
    let ell = e.length_scale().expect("bounded");
    let slab = cuboid(Vector::new(200.0 * ell, 200.0 * ell, ell));
    let wall = Shape::Plane(Plane::new(Vector::z(), 0.0).expect("plane"));
    let wall_pose = tilted(Vector::new(0.1, -0.2, 0.3), (0.2, -0.1, 0.4));
    let slab_pose = wall_pose * Pose::translation(0.0, 0.0, -ell);
    let n = wall_pose.rotation * Vector::z();
    for (k, depth) in [-1e-3, -1e-7, 1e-7, 1e-4, 1e-2].into_iter().enumerate() {
        let q = Rotation::from_euler_angles(0.3 * k as Real, 0.7, -0.2);
        let low = -e
            .convex()
            .unwrap()
            .aabb(&Pose::from_parts(
                Vector::zeros().into(),
                wall_pose.rotation.inverse() * q,
            ))
            .mins
            .z;
        let body = Pose::from_parts(
            (wall_pose * Point::new(0.05, 0.02, low - depth * ell))
                .coords
                .into(),
            q,
        );
        let (mut cache, mut scratch, mut counters) = (
            PairCache::default(),
            EpaScratch::default(),
            QueryCounters::default(),
        );
        let closed = query(
            &wall_pose,
            &wall,
            &body,
            &e,
            &mut cache,
            &mut scratch,
            &mut counters,
        )
        .expect("defined");
        let generic = contact_support_maps(
            &slab_pose,
            &slab,
            &body,
            e.convex().unwrap(),
            &tol,
            &mut PairCache::default(),
            &mut scratch,
            &mut counters,
        );
        let g = generic.geometry;
        let allowed = tol.curved_gap * ell + 1e-15 * 400.0 * ell;
        let signed = |c: &super::ContactGeometry| c.depth - c.distance;
        assert!(
            generic.converged,
            "depth {depth}: generic path did not converge: {generic:?}"
        );
        assert_eq!(closed.status, SolverStatus::Exact);
        assert!(
            (signed(&closed) - depth * ell).abs() <= 1e-15 * 10.0 * ell,
            "depth {depth}: closed form {}, expected {}",
            signed(&closed),
            depth * ell
        );
        assert!(
            (signed(&closed) - signed(&g)).abs() <= allowed,
            "depth {depth}: closed form {}, generic {}, tolerance {allowed:e}",
            signed(&closed),
            signed(&g)
        );
        assert!(
            (closed.normal - n).norm() <= 1e-15,
            "normal {:?} vs {n:?}",
            closed.normal
        );
        if depth.abs() > 1e-6 {
            let angle = closed.normal.angle(&g.normal);
            assert!(
                angle <= 1e-4,
                "depth {depth}: normals {:?} vs {:?}",
                closed.normal,
                g.normal
            );
            let dp = (closed.point_b - g.point_b).norm();
            assert!(
                dp <= 1e-4 * ell,
                "depth {depth}: points {:?} vs {:?}",
                closed.point_b,
                g.point_b
            );
        }
    }
}

/// Every pair kind with an ellipsoid, in both orders, gives the mirrored answer within the generic path's
/// tolerance and obeys c1 − c2 = δ n.
#[test]
fn both_orders_agree_for_ellipsoid_pairs() {
    let shapes = [
        (
            Shape::ellipsoid(0.5, 0.3, 0.2).expect("ellipsoid"),
            "ellipsoid",
        ),
        (
            Shape::Polyhedron(Arc::new(cuboid(Vector::repeat(0.4)))),
            "cube",
        ),
        (Shape::Sphere(Sphere::new(0.35).expect("sphere")), "sphere"),
        (
            Shape::Plane(Plane::new(Vector::z(), 0.0).expect("plane")),
            "plane",
        ),
    ];
    let pos1 = tilted(Vector::new(0.1, -0.2, 0.05), (0.1, 0.2, 0.3));
    let pos2 = tilted(Vector::new(0.4, 0.1, 0.3), (-0.3, 0.5, 0.2));
    let tol = ContactTolerances::default();
    let mut scratch = EpaScratch::default();
    let mut counters = QueryCounters::default();
    let (e, _) = &shapes[0];
    for (other, name) in &shapes {
        let ab = query(
            &pos1,
            e,
            &pos2,
            other,
            &mut PairCache::default(),
            &mut scratch,
            &mut counters,
        )
        .expect("defined");
        let ba = query(
            &pos2,
            other,
            &pos1,
            e,
            &mut PairCache::default(),
            &mut scratch,
            &mut counters,
        )
        .expect("defined");
        let ell = e
            .length_scale()
            .unwrap()
            .min(other.length_scale().unwrap_or(Real::INFINITY));
        let allowed = tol.curved_gap * ell;
        assert_eq!(ab.kind, ContactKind::Overlap, "ellipsoid-{name}: {ab:?}");
        assert!(
            (ab.depth - ba.depth).abs() <= allowed,
            "ellipsoid-{name}: depths {} vs {}, tolerance {allowed:e}",
            ab.depth,
            ba.depth
        );
        let angle = ab.normal.angle(&-ba.normal);
        assert!(
            angle <= 1e-4,
            "ellipsoid-{name}: normals {:?} vs {:?}",
            ab.normal,
            ba.normal
        );
        let diff = (ab.point_a - ab.point_b) - ab.normal * ab.depth;
        assert!(
            diff.norm() <= 1e-14 * ell,
            "ellipsoid-{name}: c1 − c2 − δ n = {diff:?}"
        );
    }
    assert_eq!(counters.fallbacks(), 0, "{counters}");
    assert_eq!(counters.support_map_unconverged, 0, "{counters}");
    assert!(
        counters.support_map >= 4 && counters.convex_plane == 2,
        "{counters}"
    );
}

/// A query stopped by the iteration caps is not "no contact": it reports its kind, the features along its
/// best direction, bounds that contain the converged answer, a fallback status, and a count.
#[test]
fn unconverged_queries_report_bounds_and_are_counted() {
    let a = Shape::ellipsoid(0.5, 0.2, 0.1).expect("ellipsoid");
    let b = Shape::ellipsoid(0.3, 0.3, 0.05).expect("ellipsoid");
    let pos1 = tilted(Vector::zeros(), (0.3, 0.1, -0.2));
    for (gap, capped, kind) in [
        (
            0.25,
            ContactTolerances {
                epa_max_iterations: 3,
                ..Default::default()
            },
            ContactKind::Overlap,
        ),
        (
            0.7,
            ContactTolerances {
                gjk_max_iterations: 2,
                ..Default::default()
            },
            ContactKind::Separated,
        ),
    ] {
        let pos2 = tilted(Vector::new(gap, 0.1, 0.05), (-0.4, 0.6, 0.1));
        let mut scratch = EpaScratch::default();
        let mut counters = QueryCounters::default();
        let (ca, cb) = (a.convex().unwrap(), b.convex().unwrap());
        let exact = contact_support_maps(
            &pos1,
            ca,
            &pos2,
            cb,
            &ContactTolerances::default(),
            &mut PairCache::default(),
            &mut scratch,
            &mut counters,
        );
        assert!(exact.converged && exact.geometry.kind == kind, "{exact:?}");
        let s = exact.geometry.depth - exact.geometry.distance;
        let mut counters = QueryCounters::default();
        let r = contact_support_maps(
            &pos1,
            ca,
            &pos2,
            cb,
            &capped,
            &mut PairCache::default(),
            &mut scratch,
            &mut counters,
        );
        assert!(!r.converged, "{r:?}");
        assert_eq!(r.geometry.kind, kind, "{r:?}");
        assert_eq!(
            r.geometry.status,
            SolverStatus::FallbackAfterMaxIterations,
            "{r:?}"
        );
        assert!(
            r.bounds[0] <= s + exact.tolerance && s <= r.bounds[1] + exact.tolerance,
            "bounds {:?} exclude the converged {s}",
            r.bounds
        );
        let reported = r.geometry.depth - r.geometry.distance;
        assert!(reported >= r.bounds[0] && reported <= r.bounds[1], "{r:?}");
        assert_eq!(
            (
                counters.support_map_unconverged,
                counters.fallback_max_iterations
            ),
            (1, 1),
            "{counters}"
        );
        // Through the dispatcher the same query says so on the geometry.
        let g = query_with(
            &pos1,
            &a,
            &pos2,
            &b,
            &capped,
            &mut PairCache::default(),
            &mut scratch,
            &mut counters,
        )
        .expect("defined");
        assert_eq!(g.status, SolverStatus::FallbackAfterMaxIterations);
    }
}
