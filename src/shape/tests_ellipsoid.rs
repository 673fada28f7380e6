//! Unit tests of the ellipsoid against closed forms and against an independent polyhedral approximation.

use super::surface_mesh::uv_surface_with;
use super::{ConvexPolyhedron, ConvexShape, Ellipsoid, Shape, ShapeError, SupportMap};
use crate::math::{Point, Pose, Real, Rotation, Vector};

fn ellipsoid(a: Real, b: Real, c: Real) -> Ellipsoid {
    Ellipsoid::new(a, b, c).expect("valid semi-axes")
}

#[test]
fn rejects_non_positive_or_non_finite_semi_axes() {
    for bad in [0.0, -1.0, Real::NAN, Real::INFINITY] {
        for k in 0..3 {
            let mut axes = [1.0, 2.0, 3.0];
            axes[k] = bad;
            let r = Shape::ellipsoid(axes[0], axes[1], axes[2]);
            assert!(
                matches!(r, Err(ShapeError::InvalidParameter { .. })),
                "semi-axes {axes:?} accepted: {r:?}"
            );
        }
    }
}

/// The support point lies on the surface, attains h(d) = |D d|, and no point of a dense surface sample
/// goes further along d.
#[test]
fn support_point_is_on_the_surface_and_maximal() {
    let e = ellipsoid(0.3, 1.2, 0.05);
    let mesh = uv_surface_with(0.3, 1.2, 0.05, 64, 128);
    let dirs = [
        Vector::new(1.0, 0.0, 0.0),
        Vector::new(0.3, -0.7, 0.2),
        Vector::new(-1e-200, 3e-201, 1e-199),
        Vector::new(5e150, 1e150, -2e150),
    ];
    for d in dirs {
        let p = e.local_support(&d, &mut 0);
        let on_surface = p.coords.component_div(&e.semi_axes()).norm();
        assert!(
            (on_surface - 1.0).abs() <= 1e-15,
            "dir {d:?}: |D⁻¹ s| = {on_surface}, expected 1"
        );
        let n = (d / d.amax()).normalize();
        let h = e.support_function(&n);
        assert!(
            (n.dot(&p.coords) - h).abs() <= 1e-15 * h,
            "dir {d:?}: n·s = {}, h = {h}",
            n.dot(&p.coords)
        );
        let sampled = mesh
            .vertices
            .iter()
            .map(|v| n.dot(&v.coords))
            .fold(Real::MIN, Real::max);
        assert!(
            sampled <= h * (1.0 + 1e-15) && sampled >= h * (1.0 - 2e-3),
            "dir {d:?}: sampled max {sampled}, support {h}"
        );
    }
}

/// Volume and principal inertia per unit density against the exact mass properties of the inscribed
/// polyhedron of a fine UV mesh. Its facets with angular step Δ deviate from the surface by a sagitta of
/// about r Δ²/8, which makes the polyhedron's volume and moments smaller by a relative O(Δ²); the test
/// allows Δ² (Δ = 2π/256 ≈ 0.025, Δ² ≈ 6e-4) and checks the polyhedron is the smaller.
#[test]
fn mass_properties_match_an_inscribed_polyhedron() {
    let (a, b, c) = (0.7, 0.2, 0.4);
    let e = ellipsoid(a, b, c);
    let mp = e.mass_properties();
    let exact_volume = 4.0 / 3.0 * std::f64::consts::PI * a * b * c;
    assert!((mp.volume - exact_volume).abs() <= 1e-15 * exact_volume);
    let mesh = uv_surface_with(a, b, c, 128, 256);
    let (poly, frame) = ConvexPolyhedron::from_points(&mesh.vertices).expect("hull");
    let pm = ConvexShape::mass_properties(&poly);
    let delta: Real = 2.0 * std::f64::consts::PI / 256.0;
    let tol = delta * delta;
    let rel = (mp.volume - pm.volume) / mp.volume;
    assert!(
        (0.0..=tol).contains(&rel),
        "volume {} vs polyhedron {}: relative {rel:e}, tolerance {tol:e}",
        mp.volume,
        pm.volume
    );
    assert!(
        frame.translation.vector.norm() <= 1e-12,
        "centroid {frame:?}"
    );
    // The polyhedron's principal axes are the ellipsoid's, in an order and sign of the hull's choosing.
    let r = frame.rotation.to_rotation_matrix().into_inner();
    let inertia_body =
        r * crate::math::Matrix::from_diagonal(&pm.principal_moments) * r.transpose();
    for k in 0..3 {
        let (want, got) = (mp.principal_moments[k], inertia_body[(k, k)]);
        let rel = (want - got) / want;
        assert!(
            (0.0..=tol).contains(&rel),
            "moment {k}: {want} vs polyhedron {got}: relative {rel:e}, tolerance {tol:e}"
        );
    }
}

/// The AABB of a rotated ellipsoid is spanned by the supports along ±world axes.
#[test]
fn aabb_is_spanned_by_supports_along_the_world_axes() {
    let e = ellipsoid(0.5, 2.0, 0.1);
    let pose = Pose::from_parts(
        Vector::new(1.0, -2.0, 3.0).into(),
        Rotation::from_euler_angles(0.3, -1.1, 0.7),
    );
    let aabb = ConvexShape::aabb(&e, &pose);
    for k in 0..3 {
        let axis = Vector::ith(k, 1.0);
        let up = pose * e.local_support(&(pose.rotation.inverse() * axis), &mut 0);
        let down = pose * e.local_support(&(pose.rotation.inverse() * -axis), &mut 0);
        assert!(
            (aabb.maxs[k] - up[k]).abs() <= 1e-14 && (aabb.mins[k] - down[k]).abs() <= 1e-14,
            "axis {k}: aabb [{}, {}], supports [{}, {}]",
            aabb.mins[k],
            aabb.maxs[k],
            down[k],
            up[k]
        );
    }
}

#[test]
fn segment_enters_only_from_outside() {
    let e = ellipsoid(1.0, 0.5, 0.25);
    let p = |x, y, z| Point::new(x, y, z);
    let cases = [
        (p(2.0, 0.0, 0.0), p(0.0, 0.0, 0.0), true),
        (p(0.0, 0.6, 0.0), p(0.0, 0.6, 1.0), false),
        (p(0.0, 0.49, -1.0), p(0.0, 0.49, 1.0), true),
        (p(0.0, 0.0, 0.0), p(3.0, 0.0, 0.0), false),
        (p(0.9, 0.3, 0.0), p(0.9, 0.3, 1.0), false),
    ];
    for (p0, p1, want) in cases {
        assert_eq!(e.segment_enters(&p0, &p1), want, "segment {p0:?} → {p1:?}");
    }
}

/// The VTK surface is closed and outward: its signed volume is positive and below the exact volume by
/// the inscribed-mesh deficit (relative ≤ Δ², Δ = π/16 the coarser angular step).
#[test]
fn surface_mesh_is_closed_and_outward() {
    let (a, b, c) = (0.3, 0.2, 0.9);
    let mesh = ellipsoid(a, b, c).surface_mesh();
    let mut volume = 0.0;
    for f in &mesh.faces {
        let [p, q, r] = [0, 1, 2].map(|k| mesh.vertices[f[k] as usize].coords);
        volume += p.dot(&q.cross(&r)) / 6.0;
    }
    let exact = 4.0 / 3.0 * std::f64::consts::PI * a * b * c;
    let delta = std::f64::consts::PI / 16.0;
    let rel = (exact - volume) / exact;
    assert!(
        (0.0..=delta * delta).contains(&rel),
        "mesh volume {volume} vs {exact}: relative deficit {rel:e}, tolerance {:e}",
        delta * delta
    );
    let mut edges = std::collections::HashMap::new();
    for f in &mesh.faces {
        for k in 0..f.len() {
            *edges.entry((f[k], f[(k + 1) % f.len()])).or_insert(0) += 1;
        }
    }
    for (&(u, v), &n) in &edges {
        assert_eq!((n, edges.get(&(v, u))), (1, Some(&1)), "edge {u}→{v}");
    }
}
