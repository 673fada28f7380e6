//! The degenerate pair set: configurations where iterative solvers meet ties, flat simplices and
//! zero-measure contacts. Coordinates are exact binary fractions wherever the configuration allows, so a
//! "touching" pair touches exactly.
//!
//! Per particle size s (h = s/2): identical axis-aligned cubes stacked face to face (touching, overlapping by
//! 1e-9 s, 1e-6 s and 0.1 s, and laterally offset); concentric cubes (identical, nested, rotated by 45°);
//! concentric regular tetrahedra (identical, point-reflected); same-orientation tetrahedra offset slightly;
//! parallel edge–edge (two cubes rotated 45° about x, edges along x; touching, overlapping, and shifted
//! along the edge); vertex on vertex (cubes with a body diagonal along z); faces resting exactly on faces
//! (a tetrahedron on a cube, a small cube on a cube).

use polydem::math::{Point, Rotation, Vector};

use super::placement::Intent;
use super::Pair;

fn cube(h: f64) -> Vec<Point> {
    let mut pts = Vec::with_capacity(8);
    for i in 0..8 {
        let s = |bit: usize| if i & bit == 0 { -h } else { h };
        pts.push(Point::new(s(1), s(2), s(4)));
    }
    pts
}

fn moved(pts: &[Point], rot: &Rotation, t: Vector) -> Vec<Point> {
    pts.iter().map(|p| rot * p + t).collect()
}

fn regular_tet(h: f64) -> Vec<Point> {
    [
        (1.0, 1.0, 1.0),
        (1.0, -1.0, -1.0),
        (-1.0, 1.0, -1.0),
        (-1.0, -1.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Point::new(x * h, y * h, z * h))
    .collect()
}

/// The degenerate set at particle sizes `sizes`.
pub fn degenerate_set(sizes: &[f64]) -> Vec<Pair> {
    let mut pairs = Vec::new();
    for (si, &s) in sizes.iter().enumerate() {
        let h = 0.5 * s;
        let id = Rotation::identity();
        let z = Vector::z();
        let mut push = |name: &str, intent: Intent, a: Vec<Point>, b: Vec<Point>| {
            pairs.push(Pair {
                id: format!("degenerate/s{si}/{name}"),
                class: "degenerate".to_string(),
                size: s,
                intent,
                a,
                b,
            });
        };
        let c = cube(h);
        push(
            "stacked_cubes_touching",
            Intent::Touching,
            c.clone(),
            moved(&c, &id, z * (2.0 * h)),
        );
        for (tag, d) in [("1e-9", 1e-9), ("1e-6", 1e-6), ("0.1", 0.1)] {
            push(
                &format!("stacked_cubes_overlap_{tag}"),
                Intent::Overlap(d * s),
                c.clone(),
                moved(&c, &id, z * (2.0 * h - d * s)),
            );
        }
        push(
            "stacked_cubes_offset_touching",
            Intent::Touching,
            c.clone(),
            moved(&c, &id, Vector::new(0.25 * h, 0.5 * h, 2.0 * h)),
        );
        push(
            "concentric_cubes_identical",
            Intent::Overlap(s),
            c.clone(),
            c.clone(),
        );
        push(
            "concentric_cubes_nested",
            Intent::Overlap(0.75 * s),
            c.clone(),
            cube(0.5 * h),
        );
        let rz45 = Rotation::from_axis_angle(&Vector::z_axis(), std::f64::consts::FRAC_PI_4);
        push(
            "concentric_cubes_rotated45",
            Intent::Overlap(s),
            c.clone(),
            moved(&c, &rz45, Vector::zeros()),
        );
        let t = regular_tet(h);
        push(
            "concentric_tets_identical",
            Intent::Overlap(s),
            t.clone(),
            t.clone(),
        );
        let reflected: Vec<Point> = t.iter().map(|p| Point::from(-p.coords)).collect();
        push(
            "concentric_tets_reflected",
            Intent::Overlap(s),
            t.clone(),
            reflected,
        );
        push(
            "same_orientation_tets_offset",
            Intent::Overlap(0.5 * s),
            t.clone(),
            moved(&t, &id, Vector::new(0.125 * h, 0.25 * h, 0.375 * h)),
        );
        let rx45 = Rotation::from_axis_angle(&Vector::x_axis(), std::f64::consts::FRAC_PI_4);
        let edge_up = moved(&c, &rx45, Vector::zeros());
        let top = edge_up
            .iter()
            .map(|p| p.z)
            .fold(f64::NEG_INFINITY, f64::max);
        let bottom = edge_up.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        let stack = top - bottom;
        push(
            "parallel_edges_touching",
            Intent::Touching,
            edge_up.clone(),
            moved(&edge_up, &id, z * stack),
        );
        push(
            "parallel_edges_overlap_1e-3",
            Intent::Overlap(1e-3 * s),
            edge_up.clone(),
            moved(&edge_up, &id, z * (stack - 1e-3 * s)),
        );
        push(
            "parallel_edges_shifted_overlap_1e-3",
            Intent::Overlap(1e-3 * s),
            edge_up.clone(),
            moved(&edge_up, &id, Vector::new(h, 0.0, stack - 1e-3 * s)),
        );
        let diag = Rotation::rotation_between(&Vector::new(1.0, 1.0, 1.0), &z).unwrap_or(id);
        let vertex_up = moved(&c, &diag, Vector::zeros());
        let vtop = vertex_up
            .iter()
            .map(|p| p.z)
            .fold(f64::NEG_INFINITY, f64::max);
        let vbottom = vertex_up.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        push(
            "vertex_on_vertex_touching",
            Intent::Touching,
            vertex_up.clone(),
            moved(&vertex_up, &id, z * (vtop - vbottom)),
        );
        push(
            "vertex_on_vertex_overlap_1e-3",
            Intent::Overlap(1e-3 * s),
            vertex_up.clone(),
            moved(&vertex_up, &id, z * (vtop - vbottom - 1e-3 * s)),
        );
        let tet_on_face = vec![
            Point::new(-0.5 * h, -0.5 * h, h),
            Point::new(0.5 * h, -0.5 * h, h),
            Point::new(0.0, 0.5 * h, h),
            Point::new(0.0, 0.0, 2.0 * h),
        ];
        push(
            "face_on_face_tet_on_cube",
            Intent::Touching,
            c.clone(),
            tet_on_face,
        );
        let small: Vec<Point> = cube(0.25 * h)
            .iter()
            .map(|p| p + Vector::new(0.0, 0.0, 1.25 * h))
            .collect();
        push(
            "face_on_face_small_cube_on_cube",
            Intent::Touching,
            c.clone(),
            small,
        );
    }
    pairs
}
