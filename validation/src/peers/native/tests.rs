//! Every compiled-in peer on two boxes side by side: the answer's kind, value and normal direction (world,
//! from the first body to the second) against the construction.

use super::{NativeAnswer, NativePair, NativePeer};
use polydem::contact::tolerances::pair_length_scale;
use polydem::math::{Point, Rotation, Vector};
use polydem::shape::ConvexPolyhedron;

/// The rotation of both boxes: a generic one, so that no body frame is the world's.
fn turn() -> Rotation {
    Rotation::from_euler_angles(0.4, -0.7, 1.1)
}

/// Two 1 × 0.8 × 0.6 boxes with the same rotation, B's centre (1 − `overlap`, 0.15, −0.1) from A's in the
/// turned axes: they overlap by `overlap` (or are −`overlap` apart) across their x faces, and that axis is
/// the minimal one (the overlaps along y and z are 0.65 and 0.5). The shift along y and z keeps the side
/// faces apart, a degenerate configuration that is not this test's subject.
fn boxes(overlap: f64) -> NativePair {
    let corners = |centre: Vector| -> Vec<Point> {
        (0..8)
            .map(|i| {
                let c = |bit: usize, h: f64| if i & bit == 0 { -h } else { h };
                Point::from(turn() * Vector::new(c(1, 0.5), c(2, 0.4), c(4, 0.3)) + centre)
            })
            .collect()
    };
    let offset = turn() * Vector::new(1.0 - overlap, 0.15, -0.1);
    let (a, pos1) =
        ConvexPolyhedron::from_points(&corners(Vector::new(0.2, -0.1, 0.3))).expect("box A");
    let (b, pos2) = ConvexPolyhedron::from_points(&corners(Vector::new(0.2, -0.1, 0.3) + offset))
        .expect("box B");
    let size = pair_length_scale(a.length_scale(), b.length_scale());
    NativePair::new(&a, &pos1, &b, &pos2, size)
}

fn along_x(n: &Vector) -> bool {
    (n - turn() * Vector::x()).norm() <= 1e-6
}

#[test]
fn peers_answer_boxes_with_world_normals_from_first_to_second() {
    let (overlapping, separated) = (boxes(0.1), boxes(-0.1));
    for peer in NativePeer::ALL.into_iter().filter(|p| p.available()) {
        match overlapping.answer(peer) {
            NativeAnswer::Overlap {
                depth,
                normal: Some(normal),
            } => assert!(
                (depth - 0.1).abs() <= 1e-6 && along_x(&normal),
                "{}: overlapping boxes (overlap 0.1 along the turned x axis {:?}): depth {depth}, \
                 normal {normal:?}; expected 0.1 within 1e-6 and that axis within 1e-6",
                peer.label(),
                turn() * Vector::x()
            ),
            other => panic!("{}: overlapping boxes answered {other:?}", peer.label()),
        }
        match separated.answer(peer) {
            NativeAnswer::Separated {
                distance: Some(d),
                normal: Some(n),
            } => assert!(
                (d - 0.1).abs() <= 1e-6 && along_x(&n),
                "{}: boxes 0.1 apart along the turned x axis {:?}: distance {d}, normal {n:?}; \
                 expected 0.1 within 1e-6 and that axis within 1e-6",
                peer.label(),
                turn() * Vector::x()
            ),
            NativeAnswer::Separated { distance: None, .. } if !peer.gives_distance() => {}
            other => panic!("{}: separated boxes answered {other:?}", peer.label()),
        }
    }
}
