//! Seeded point clouds of the shape classes, at unit size (the points' bounding radius about their mean is
//! 0.5, i.e. particle diameter 1); the caller scales them.
//!
//! - `tet`: 4 random points on the unit sphere, rejected when the tetrahedron's volume is below 5 % of the
//!   regular one inscribed in the same sphere (no slivers here; slivers belong to the stress tests).
//! - `box`: a cuboid with half-extents whose ratios are up to 3:1.
//! - `hullN` (N = 8, 16, 32, 64): N points uniformly distributed in direction on an ellipsoid with semi-axes
//!   (1, b, c), b, c uniform in [1/3, 1] (aspect up to 3:1); every point is a hull vertex.
//! - `voronoi`: a Voronoi-like cell: the cell of the origin among 40 points drawn uniformly in a ball of
//!   radius 1 around it (the intersection of the half-spaces bounded by the bisector planes, closed by a cube
//!   of half-width 2), accepted when it has 20 to 40 vertices (typically ~27, as for Poisson-Voronoi cells).
//!   Its vertices are found by intersecting every triple of planes and keeping the points inside all
//!   half-spaces.

use polydem::math::{Point, Rotation, Vector};
use rand::Rng;

/// The shape classes of the random pair sets, in report order.
pub const CLASSES: [&str; 7] = [
    "tet", "box", "hull8", "hull16", "hull32", "hull64", "voronoi",
];

/// A uniformly distributed unit vector.
pub fn random_unit(rng: &mut impl Rng) -> Vector {
    let z: f64 = rng.random_range(-1.0..1.0);
    let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vector::new(r * phi.cos(), r * phi.sin(), z)
}

/// A uniformly distributed rotation (Shoemake's method).
pub fn random_rotation(rng: &mut impl Rng) -> Rotation {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = nalgebra::Quaternion::new(
        b * (tau * u3).cos(),
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
    );
    Rotation::from_quaternion(q)
}

fn normalise_size(mut pts: Vec<Point>) -> Vec<Point> {
    let n = pts.len() as f64;
    let mean = pts.iter().fold(Vector::zeros(), |s, p| s + p.coords) / n;
    let r = pts
        .iter()
        .map(|p| (p.coords - mean).norm())
        .fold(0.0, f64::max);
    for p in &mut pts {
        *p = Point::from((p.coords - mean) * (0.5 / r));
    }
    pts
}

fn tetrahedron(rng: &mut impl Rng) -> Vec<Point> {
    // Regular tetrahedron inscribed in the unit sphere: volume 8/(9√3).
    let regular = 8.0 / (9.0 * 3f64.sqrt());
    loop {
        let p: Vec<Vector> = (0..4).map(|_| random_unit(rng)).collect();
        let vol = (p[1] - p[0])
            .cross(&(p[2] - p[0]))
            .dot(&(p[3] - p[0]))
            .abs()
            / 6.0;
        if vol >= 0.05 * regular {
            return normalise_size(p.into_iter().map(Point::from).collect());
        }
    }
}

fn cuboid(rng: &mut impl Rng) -> Vec<Point> {
    let h = Vector::new(
        1.0,
        rng.random_range(1.0 / 3.0..1.0),
        rng.random_range(1.0 / 3.0..1.0),
    );
    let mut pts = Vec::with_capacity(8);
    for i in 0..8 {
        let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
        pts.push(Point::new(s(1) * h.x, s(2) * h.y, s(4) * h.z));
    }
    normalise_size(pts)
}

fn ellipsoid_hull(rng: &mut impl Rng, n: usize) -> Vec<Point> {
    let axes = Vector::new(
        1.0,
        rng.random_range(1.0 / 3.0..1.0),
        rng.random_range(1.0 / 3.0..1.0),
    );
    normalise_size(
        (0..n)
            .map(|_| Point::from(random_unit(rng).component_mul(&axes)))
            .collect(),
    )
}

fn voronoi_cell(rng: &mut impl Rng) -> Vec<Point> {
    loop {
        // Half-spaces n·x ≤ d.
        let mut planes: Vec<(Vector, f64)> = (0..40)
            .map(|_| {
                let r: f64 = rng.random::<f64>().cbrt();
                let p = random_unit(rng) * r.max(1e-3);
                (p, 0.5 * p.norm_squared())
            })
            .collect();
        for axis in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut n = Vector::zeros();
                n[axis] = sign;
                planes.push((n, 2.0));
            }
        }
        let mut verts: Vec<Point> = Vec::new();
        let m = planes.len();
        for i in 0..m {
            for j in i + 1..m {
                for k in j + 1..m {
                    let (a, b, c) = (&planes[i], &planes[j], &planes[k]);
                    let mat = nalgebra::Matrix3::from_rows(&[
                        a.0.transpose(),
                        b.0.transpose(),
                        c.0.transpose(),
                    ]);
                    let Some(inv) = mat.try_inverse() else {
                        continue;
                    };
                    if mat.determinant().abs() < 1e-9 * a.0.norm() * b.0.norm() * c.0.norm() {
                        continue;
                    }
                    let x = inv * Vector::new(a.1, b.1, c.1);
                    let inside = planes
                        .iter()
                        .all(|(n, d)| n.dot(&x) <= d + 1e-12 * n.norm());
                    if inside && !verts.iter().any(|v| (v.coords - x).norm() < 1e-9) {
                        verts.push(Point::from(x));
                    }
                }
            }
        }
        if (20..=40).contains(&verts.len()) {
            return normalise_size(verts);
        }
    }
}

/// A random point cloud of `class` at unit size, in a random orientation. `None` for an unknown class.
pub fn random_shape(class: &str, rng: &mut impl Rng) -> Option<Vec<Point>> {
    let pts = match class {
        "tet" => tetrahedron(rng),
        "box" => cuboid(rng),
        "hull8" => ellipsoid_hull(rng, 8),
        "hull16" => ellipsoid_hull(rng, 16),
        "hull32" => ellipsoid_hull(rng, 32),
        "hull64" => ellipsoid_hull(rng, 64),
        "voronoi" => voronoi_cell(rng),
        _ => return None,
    };
    let rot = random_rotation(rng);
    Some(pts.into_iter().map(|p| rot * p).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn classes_have_unit_size_and_expected_vertex_counts() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for class in CLASSES {
            let pts = random_shape(class, &mut rng).unwrap();
            let mean = pts.iter().fold(Vector::zeros(), |s, p| s + p.coords) / pts.len() as f64;
            let r = pts
                .iter()
                .map(|p| (p.coords - mean).norm())
                .fold(0.0, f64::max);
            assert!(
                (r - 0.5).abs() < 1e-12,
                "class {class}: bounding radius {r}, expected 0.5"
            );
            let expected = match class {
                "tet" => 4..=4,
                "box" => 8..=8,
                "hull8" => 8..=8,
                "hull16" => 16..=16,
                "hull32" => 32..=32,
                "hull64" => 64..=64,
                _ => 20..=40,
            };
            assert!(
                expected.contains(&pts.len()),
                "class {class}: {} points, expected {expected:?}",
                pts.len()
            );
        }
    }
}
