//! Property-based fuzzing of shape construction and the contact core (stability stress tests).
//!
//! Random and adversarial inputs — clouds at scales from 1e-6 to 1e6, far from the origin, nearly coplanar —
//! must never panic or produce non-finite output. Every polyhedron that is built must
//! contain its input points; every pair query must agree with the exact SAT oracle on the kind of contact
//! and on the Minkowski overlap, and its normal must be an optimal axis. proptest shrinks any failure to a
//! small reproducible input. 256 cases per property by default; `PROPTEST_CASES=20000` runs a deeper fuzz (the
//! deeper run passed in 16 s).

use nalgebra::{Translation3, UnitQuaternion};
use polydem::contact::{query_polyhedra, sat_polyhedra, ContactKind};
use polydem::math::{Point, Pose, Real, Vector};
use polydem::shape::ConvexPolyhedron;
use proptest::prelude::*;

/// A direction in the unit ball's surface, from three numbers (rejecting the degenerate zero vector).
fn unit(x: Real, y: Real, z: Real) -> Vector {
    let v = Vector::new(x, y, z);
    if v.norm() < 1e-3 {
        Vector::x()
    } else {
        v.normalize()
    }
}

/// A cloud of `n` points on an ellipsoid with semi-axes up to 3:1, radius `size`, centred at `offset`.
fn ellipsoid_cloud() -> impl Strategy<Value = (Vec<Point>, Real)> {
    (
        prop::collection::vec((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), 4..40),
        (1.0..3.0f64, 1.0..3.0f64),
        -6i32..7,
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        0.0..3.0f64,
    )
        .prop_map(|(dirs, (ay, az), exponent, (ox, oy, oz), offset_decades)| {
            let size = 10f64.powi(exponent);
            // The offset puts the cloud up to 10^3 sizes away from the origin: coordinates carry fewer
            // significant digits of the shape, as they do far from a scene's origin.
            let offset = Vector::new(ox, oy, oz) * size * 10f64.powf(offset_decades);
            let points = dirs
                .into_iter()
                .map(|(x, y, z)| {
                    let d = unit(x, y, z);
                    Point::from(Vector::new(d.x, d.y / ay, d.z / az) * size + offset)
                })
                .collect();
            (points, size)
        })
}

/// Points on a randomly oriented plane, lifted out of it by a relative noise of 1e-2 … 1e-15.
fn nearly_coplanar_cloud() -> impl Strategy<Value = Vec<Point>> {
    (
        prop::collection::vec((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), 4..30),
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        2i32..16,
    )
        .prop_map(|(coords, (nx, ny, nz), noise_decades)| {
            let normal = unit(nx, ny, nz);
            let noise = 10f64.powi(-noise_decades);
            coords
                .into_iter()
                .map(|(u, v, w)| {
                    let p = Vector::new(u, v, 0.0);
                    let rot = UnitQuaternion::rotation_between(&Vector::z(), &normal)
                        .unwrap_or_else(UnitQuaternion::identity);
                    Point::from(rot * (p + Vector::z() * w * noise))
                })
                .collect()
        })
}

fn rotation() -> impl Strategy<Value = UnitQuaternion<Real>> {
    (
        -1.0..1.0f64,
        -1.0..1.0f64,
        -1.0..1.0f64,
        0.0..std::f64::consts::PI,
    )
        .prop_map(|(x, y, z, angle)| {
            UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(unit(x, y, z)), angle)
        })
}

/// Largest distance of a point outside the polyhedron (placed at `pose`), over all faces.
fn outside_distance(shape: &ConvexPolyhedron, pose: &Pose, p: &Point) -> Real {
    let local = pose.inverse_transform_point(p);
    (0..shape.num_faces())
        .map(|f| shape.face_normal(f).dot(&local.coords) - shape.face_offset(f))
        .fold(Real::NEG_INFINITY, Real::max)
}

/// Overlap of A and B along the unit direction `n` (from A to B): h_A(n) + h_B(−n), by brute force.
fn overlap_along(
    a: &ConvexPolyhedron,
    pos1: &Pose,
    b: &ConvexPolyhedron,
    pos2: &Pose,
    n: &Vector,
) -> Real {
    let max_a = a
        .vertices()
        .iter()
        .map(|v| n.dot(&(pos1 * v).coords))
        .fold(Real::NEG_INFINITY, Real::max);
    let min_b = b
        .vertices()
        .iter()
        .map(|v| n.dot(&(pos2 * v).coords))
        .fold(Real::INFINITY, Real::min);
    max_a - min_b
}

proptest! {
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn hull_of_any_cloud_is_an_error_or_contains_every_point((points, size) in ellipsoid_cloud()) {
        let far = points.iter().map(|p| p.coords.amax()).fold(0.0, Real::max);
        match ConvexPolyhedron::from_points(&points) {
            Err(_) => {} // a typed error is an acceptable answer; a panic is not
            Ok((shape, pose)) => {
                let volume = shape.mass_properties().volume;
                prop_assert!(volume.is_finite() && volume > 0.0, "volume {volume} for size {size}");
                // Round-off of coordinates of magnitude `far` is ~1e-16 far; allow 1e-9 of the size on top.
                let tol = 1e-9 * size + 1e-13 * far;
                for (k, p) in points.iter().enumerate() {
                    let out = outside_distance(&shape, &pose, p);
                    prop_assert!(out <= tol, "point {k} {p:?} is {out:e} outside the hull (tolerance {tol:e}, size {size:e})");
                }
            }
        }
    }

    #[test]
    fn nearly_coplanar_clouds_never_panic_and_give_finite_solids(points in nearly_coplanar_cloud()) {
        if let Ok((shape, _pose)) = ConvexPolyhedron::from_points(&points) {
            let m = shape.mass_properties();
            prop_assert!(m.volume.is_finite() && m.volume > 0.0, "volume {}", m.volume);
            prop_assert!(m.principal_moments.iter().all(|x| x.is_finite() && *x > 0.0), "moments {:?}", m.principal_moments);
            prop_assert!(shape.vertices().iter().all(|v| v.coords.iter().all(|c| c.is_finite())));
        }
    }

    #[test]
    fn pair_query_agrees_with_the_exact_oracle(
        (cloud_a, size_a) in ellipsoid_cloud(),
        (cloud_b, _) in ellipsoid_cloud(),
        rot_a in rotation(),
        rot_b in rotation(),
        (dx, dy, dz) in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        reach in 0.0..2.5f64,
    ) {
        // Both shapes at the scale of A (B's cloud is rescaled), B's centre at `reach` radii from A's.
        let Ok((a, _)) = ConvexPolyhedron::from_points(&cloud_a) else { return Ok(()) };
        let Ok((b_raw, _)) = ConvexPolyhedron::from_points(&cloud_b) else { return Ok(()) };
        let rescale = a.bounding_radius() / b_raw.bounding_radius();
        let b_points: Vec<Point> = b_raw.vertices().iter().map(|v| Point::from(v.coords * rescale)).collect();
        let Ok((b, _)) = ConvexPolyhedron::from_points(&b_points) else { return Ok(()) };
        let scale = a.length_scale().max(b.length_scale());
        let pos1 = Pose::from_parts(Translation3::from(Vector::new(0.3, -0.2, 0.1) * size_a), rot_a);
        let shift = unit(dx, dy, dz) * reach * a.bounding_radius();
        let pos2 = Pose::from_parts(Translation3::from(pos1.translation.vector + shift), rot_b);

        let ours = query_polyhedra(&pos1, &a, &pos2, &b);
        let exact = sat_polyhedra(&pos1, &a, &pos2, &b);
        let inputs = format!("pos1 {pos1:?}\npos2 {pos2:?}\nA {:?}\nB {:?}", a.vertices(), b.vertices());

        let finite = [ours.depth, ours.distance].iter().chain(ours.normal.iter()).chain(ours.point_a.coords.iter())
            .chain(ours.point_b.coords.iter()).all(|x| x.is_finite());
        prop_assert!(finite, "non-finite output {ours:?}\n{inputs}");
        prop_assert!((ours.normal.norm() - 1.0).abs() < 1e-9, "normal not unit: {:?}\n{inputs}", ours.normal);
        prop_assert!(ours.depth >= 0.0 && ours.distance >= 0.0, "negative depth/distance {ours:?}");

        // A kind may differ from the oracle's only when the exact answer lies within a few touching bands.
        let band = 1e-10 * scale;
        let borderline = exact.depth.max(exact.distance) <= 10.0 * band;
        prop_assert!(ours.kind == exact.kind || borderline,
            "kind {:?}, oracle {:?} (oracle depth {:e}, distance {:e})\n{inputs}", ours.kind, exact.kind, exact.depth, exact.distance);

        if exact.kind == ContactKind::Overlap && ours.kind == ContactKind::Overlap {
            let tol = 1e-10 * scale + 1e-9 * exact.depth;
            prop_assert!((ours.depth - exact.depth).abs() <= tol,
                "depth {:e}, oracle {:e}, |error| {:e} > tolerance {tol:e}\n{inputs}", ours.depth, exact.depth, (ours.depth - exact.depth).abs());
            let along = overlap_along(&a, &pos1, &b, &pos2, &ours.normal);
            prop_assert!((along - exact.depth).abs() <= tol,
                "overlap along the reported normal {along:e} differs from the exact depth {:e} by more than {tol:e}\n{inputs}", exact.depth);
        }
        if exact.kind == ContactKind::Separated && ours.kind == ContactKind::Separated {
            let tol = 1e-10 * scale + 1e-9 * exact.distance;
            prop_assert!((ours.distance - exact.distance).abs() <= tol,
                "distance {:e}, oracle {:e} (tolerance {tol:e})\n{inputs}", ours.distance, exact.distance);
        }
    }
}

/// A hull of `n` seeded points on an ellipsoid of semi-axes (1, 0.8, 0.6) × `radius` about the origin.
fn seeded_hull(rng: &mut rand_chacha::ChaCha8Rng, n: usize, radius: Real) -> ConvexPolyhedron {
    use rand::Rng;
    let points: Vec<Point> = (0..n)
        .map(|_| {
            let d = unit(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            Point::new(d.x, 0.8 * d.y, 0.6 * d.z) * radius
        })
        .collect();
    ConvexPolyhedron::from_points(&points)
        .expect("a seeded ellipsoid cloud has a hull")
        .0
}

fn seeded_rotation(rng: &mut rand_chacha::ChaCha8Rng) -> UnitQuaternion<Real> {
    use rand::Rng;
    let axis = unit(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    UnitQuaternion::from_scaled_axis(axis * rng.random_range(0.0..std::f64::consts::PI))
}

/// Pebble–boulder pairs (size ratios 1e2 … 1e5): a pebble hull resting on the top face of a rotated box
/// boulder, placed so that its lowest vertex along the face normal is `s` inside (s > 0) or |s| outside
/// (s < 0) the face, |s| from 1e-9 to 1e-3 of the pebble's size. The face is wider than the pebble by far, so
/// the exact answer is the constructed one: overlap s, or gap |s|, to the round-off of coordinates of the
/// boulder's size. Both the query and the SAT oracle must return that status, in both pair orders: the
/// touching band follows the smaller body, so no such pair may come back as touching.
#[test]
fn pebble_on_boulder_pairs_have_the_constructed_status() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(20261128);
    let mut wrong = Vec::new();
    let mut checked = 0;
    for ratio in [1e2, 1e3, 1e4, 1e5] {
        for trial in 0..4 {
            let boulder_half = Vector::new(1.0, 0.7, 0.4);
            let corners: Vec<Point> = (0..8)
                .map(|i| {
                    let s = |bit: usize, h: Real| if i & bit == 0 { -h } else { h };
                    Point::new(
                        s(1, boulder_half.x),
                        s(2, boulder_half.y),
                        s(4, boulder_half.z),
                    )
                })
                .collect();
            let boulder = ConvexPolyhedron::from_points(&corners)
                .expect("a box has a hull")
                .0;
            let pebble = seeded_hull(&mut rng, 16, 2.0 / ratio);
            let rot_b = seeded_rotation(&mut rng);
            let centre_b = unit(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            ) * 3.0;
            let pos_b = Pose::from_parts(Translation3::from(centre_b), rot_b);
            let n = rot_b * Vector::z();
            let on_face = pos_b
                * Point::new(
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.3..0.3),
                    boulder_half.z,
                );
            let rot_p = seeded_rotation(&mut rng);
            let lowest = pebble
                .vertices()
                .iter()
                .map(|v| n.dot(&(rot_p * v.coords)))
                .fold(Real::INFINITY, Real::min);
            let size = pebble.length_scale();
            for decade in 3..=9 {
                for sign in [1.0, -1.0] {
                    let s = sign * size * 10f64.powi(-decade);
                    let centre_p = on_face.coords + n * (-s - lowest);
                    let pos_p = Pose::from_parts(Translation3::from(centre_p), rot_p);
                    let want = if s > 0.0 {
                        ContactKind::Overlap
                    } else {
                        ContactKind::Separated
                    };
                    for (order, (pos1, a, pos2, b)) in [
                        (&pos_p, &pebble, &pos_b, &boulder),
                        (&pos_b, &boulder, &pos_p, &pebble),
                    ]
                    .into_iter()
                    .enumerate()
                    {
                        let ours = query_polyhedra(pos1, a, pos2, b);
                        let exact = sat_polyhedra(pos1, a, pos2, b);
                        checked += 1;
                        for (who, g) in [("query", &ours), ("SAT oracle", &exact)] {
                            if g.kind != want {
                                wrong.push(format!(
                                    "ratio {ratio:e}, trial {trial}, s = {s:e} (= {:e} × pebble size), order {order}: {who} says {:?} (depth {:e}, distance {:e}), want {want:?}",
                                    s / size, g.kind, g.depth, g.distance
                                ));
                            }
                        }
                        // Coordinates of the boulder's size carry round-off of ~ε·(|centre| + size); the value
                        // must match the constructed one within a few of those and 1e-9 of itself.
                        let round_off = 64.0 * Real::EPSILON * 6.0;
                        let value = ours.depth - ours.distance;
                        if ours.kind == want && (value - s).abs() > round_off + 1e-9 * s.abs() {
                            wrong.push(format!(
                                "ratio {ratio:e}, trial {trial}, order {order}: signed overlap {value:e}, constructed {s:e}, |error| {:e} > {:e}",
                                (value - s).abs(), round_off + 1e-9 * s.abs()
                            ));
                        }
                    }
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "{} wrong answers of {checked} pebble–boulder queries:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
}
