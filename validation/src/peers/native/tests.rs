//! Every compiled-in peer on two unit cubes side by side along x: the answer's kind, value and normal
//! direction (from the first body to the second) against the construction.

use super::{NativeAnswer, NativePair, NativePeer};
use polydem::contact::tolerances::pair_length_scale;
use polydem::math::{Point, Vector};
use polydem::shape::ConvexPolyhedron;

/// Cube A of side 1 at the origin, cube B of side 1 at x = 1 − `overlap` (rotated 0.3 rad about x, so
/// the contact face stays normal to x).
fn cubes(overlap: f64) -> NativePair {
    let corners = |cx: f64, turn: f64| -> Vec<Point> {
        let rot = polydem::math::Rotation::from_axis_angle(&Vector::x_axis(), turn);
        (0..8)
            .map(|i| {
                let c = |bit: usize| if i & bit == 0 { -0.5 } else { 0.5 };
                Point::from(rot * Vector::new(c(1), c(2), c(4)) + Vector::new(cx, 0.0, 0.0))
            })
            .collect()
    };
    let (a, pos1) = ConvexPolyhedron::from_points(&corners(0.0, 0.0)).expect("cube A");
    let (b, pos2) = ConvexPolyhedron::from_points(&corners(1.0 - overlap, 0.3)).expect("cube B");
    let size = pair_length_scale(a.length_scale(), b.length_scale());
    NativePair::new(&a, &pos1, &b, &pos2, size)
}

fn along_x(n: &Vector) -> bool {
    (n - Vector::x()).norm() <= 1e-6
}

#[test]
fn peers_answer_cubes_with_normals_from_first_to_second() {
    let (overlapping, separated) = (cubes(0.1), cubes(-0.1));
    for peer in NativePeer::ALL.into_iter().filter(|p| p.available()) {
        match overlapping.answer(peer) {
            NativeAnswer::Overlap {
                depth,
                normal: Some(normal),
            } => assert!(
                (depth - 0.1).abs() <= 1e-6 && along_x(&normal),
                "{}: overlapping cubes (overlap 0.1 along +x): depth {depth}, normal {normal:?}; \
                 expected 0.1 within 1e-6 and +x within 1e-6",
                peer.label()
            ),
            other => panic!("{}: overlapping cubes answered {other:?}", peer.label()),
        }
        match separated.answer(peer) {
            NativeAnswer::Separated {
                distance: Some(d),
                normal: Some(n),
            } => assert!(
                (d - 0.1).abs() <= 1e-6 && along_x(&n),
                "{}: cubes 0.1 apart along +x: distance {d}, normal {n:?}; expected 0.1 within 1e-6 \
                 and +x within 1e-6",
                peer.label()
            ),
            NativeAnswer::Separated { distance: None, .. } if !peer.gives_distance() => {}
            other => panic!("{}: separated cubes answered {other:?}", peer.label()),
        }
    }
}
