//! Sphere–sphere contact, in closed form.
//!
//! With centres c_A, c_B at distance d and radii r_A, r_B: n = (c_B − c_A)/d, δ = r_A + r_B − d,
//! c1 = c_A + r_A n, c2 = c_B − r_B n (so c1 − c2 = δ n). Concentric spheres have no preferred direction;
//! the normal is then the world x axis, deterministically. Exact up to round-off; status `Exact`.

use super::tolerances::{pair_length_scale, ContactTolerances};
use super::{ContactGeometry, ContactKind, SolverStatus};
use crate::math::{Point, Real, Vector};

/// Contact of the sphere (centre `c1`, radius `r1`) with the sphere (`c2`, `r2`), world frame. The
/// touching band follows the smaller diameter (floored as [`pair_length_scale`] floors it), the scale at
/// which the pair's force and energy error live.
pub fn contact_sphere_sphere(
    c1: &Point,
    r1: Real,
    c2: &Point,
    r2: Real,
    tol: &ContactTolerances,
) -> ContactGeometry {
    let touch = tol.touching * pair_length_scale(2.0 * r1, 2.0 * r2);
    let d_vec = c2 - c1;
    let (normal, signed) = sphere_sphere_normal(&d_vec, d_vec.norm_squared(), r1 + r2);
    let (point_a, point_b) = sphere_sphere_points(c1, r1, c2, r2, &normal);
    let (kind, depth, distance) = classify(signed, touch);
    ContactGeometry::from_points(
        kind,
        depth,
        distance,
        normal,
        point_a,
        point_b,
        SolverStatus::Exact,
    )
}

/// The unit normal n (from sphere 1 to sphere 2; the world x axis for concentric spheres) and the signed
/// overlap `reach` − d (m) of two spheres whose centres are `d_vec` = c₂ − c₁ apart, with `d_squared` =
/// |d_vec|² and `reach` = r₁ + r₂. The closed form every path that meets two spheres takes (the general
/// narrow phase through [`contact_sphere_sphere`], the flat sphere layout's pair loop directly, which has
/// |d_vec|² from its cheap test); d is √|d_vec|² as `norm` forms it.
#[inline(always)]
pub fn sphere_sphere_normal(d_vec: &Vector, d_squared: Real, reach: Real) -> (Vector, Real) {
    let d = d_squared.sqrt();
    let normal = if d > 0.0 { d_vec / d } else { Vector::x() };
    (normal, reach - d)
}

/// The surface points c₁ + r₁ n and c₂ − r₂ n of two spheres along the normal n of
/// [`sphere_sphere_normal`] (c1 − c2 = δ n).
#[inline(always)]
pub fn sphere_sphere_points(
    c1: &Point,
    r1: Real,
    c2: &Point,
    r2: Real,
    normal: &Vector,
) -> (Point, Point) {
    (c1 + normal * r1, c2 - normal * r2)
}

/// Kind, depth and distance from a signed overlap (positive = overlap) and the touching band.
pub(crate) fn classify(signed: Real, touch: Real) -> (ContactKind, Real, Real) {
    if signed > touch {
        (ContactKind::Overlap, signed, 0.0)
    } else if signed < -touch {
        (ContactKind::Separated, 0.0, -signed)
    } else {
        (ContactKind::Touching, 0.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_spheres_closed_form() {
        let tol = ContactTolerances::default();
        for scale in [1e-3, 1.0, 1e3] {
            let g = contact_sphere_sphere(
                &Point::new(0.0, 0.0, 0.0),
                1.0 * scale,
                &Point::new(3.0, 4.0, 0.0).map(|x| x * scale * 0.3),
                0.6 * scale,
                &tol,
            );
            // d = 1.5 s, δ = 1.6 s − 1.5 s = 0.1 s.
            let want = 0.1 * scale;
            assert_eq!(g.kind, ContactKind::Overlap, "scale {scale}: {g:?}");
            assert!(
                (g.depth - want).abs() <= 1e-14 * scale,
                "depth {} want {want}",
                g.depth
            );
            assert!(
                (g.normal - Vector::new(0.6, 0.8, 0.0)).norm() < 1e-15,
                "normal {:?}",
                g.normal
            );
            let diff = (g.point_a - g.point_b) - g.normal * g.depth;
            assert!(diff.norm() <= 1e-14 * scale, "c1 − c2 − δn = {diff:?}");
        }
    }

    #[test]
    fn separated_and_touching_spheres() {
        let tol = ContactTolerances::default();
        let g = contact_sphere_sphere(&Point::origin(), 1.0, &Point::new(0.0, 0.0, 2.5), 1.0, &tol);
        assert_eq!(g.kind, ContactKind::Separated);
        assert!((g.distance - 0.5).abs() < 1e-15, "distance {}", g.distance);
        let g = contact_sphere_sphere(&Point::origin(), 1.0, &Point::new(0.0, 0.0, 2.0), 1.0, &tol);
        assert_eq!(g.kind, ContactKind::Touching, "{g:?}");
        let g = contact_sphere_sphere(&Point::origin(), 1.0, &Point::origin(), 0.5, &tol);
        assert_eq!(g.kind, ContactKind::Overlap);
        assert!(
            (g.depth - 1.5).abs() < 1e-15 && g.normal == Vector::x(),
            "{g:?}"
        );
    }

    /// A pebble against a boulder 1e4 times larger: a gap or an overlap of 1e-9 of the pebble's diameter
    /// is far above the round-off of the centre distance (a few ε · 10 m) and must not fall in the
    /// touching band, which follows the pebble.
    #[test]
    fn pebble_boulder_band_follows_the_pebble() {
        let tol = ContactTolerances::default();
        let (r_boulder, r_pebble) = (10.0, 1e-3);
        let band = tol.touching * pair_length_scale(2.0 * r_boulder, 2.0 * r_pebble);
        for signed_gap in [1e-9 * 2.0 * r_pebble, -1e-9 * 2.0 * r_pebble] {
            let centre = Point::new(r_boulder + r_pebble + signed_gap, 0.0, 0.0);
            let g = contact_sphere_sphere(&Point::origin(), r_boulder, &centre, r_pebble, &tol);
            let expected = if signed_gap > 0.0 {
                ContactKind::Separated
            } else {
                ContactKind::Overlap
            };
            assert_eq!(
                g.kind, expected,
                "radii {r_boulder} and {r_pebble}, gap {signed_gap:e} m, band {band:e} m: {g:?}"
            );
        }
    }
}
