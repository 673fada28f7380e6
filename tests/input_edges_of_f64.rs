//! Inputs at the edges of f64 and of the file formats: each is either handled or refused with a message
//! that states the real limit, never with an internal message of the hull builder or a parse error about
//! an invisible character.
//!
//! - Distinct points 1e-300 apart: the squared extent underflows to 0, and they were reported as "all points
//!   coincide"; a valid tetrahedron 1e-160 across failed inside the hull builder. Both are outside the sizes
//!   whose mass properties (∝ size⁵) f64 holds, and are refused with that range.
//! - A 1 mm cube 1e11 m from the origin failed with "merged face has no boundary": its coordinates' round-off
//!   is as large as the cube. It is refused with the size a shape needs there.
//! - A UTF-8 byte-order mark at the start of a contact-pairs file was reported as invalid JSON; it is
//!   skipped, as it is in a scene file and a body file.

use std::io::Write as _;

use polydem::io::pairs_jsonl::answer_stream;
use polydem::math::{Point, Real};
use polydem::shape::{ConvexPolyhedron, ShapeError, MAX_EXTENT, MIN_EXTENT};

fn tetrahedron(size: Real, offset: Real) -> Vec<Point> {
    vec![
        Point::new(offset, offset, offset),
        Point::new(offset + size, offset, offset),
        Point::new(offset, offset + size, offset),
        Point::new(offset, offset, offset + size),
    ]
}

fn cube(side: Real, offset: Real) -> Vec<Point> {
    (0..8)
        .map(|i| {
            let c = |bit: usize| offset + if i & (1 << bit) != 0 { side } else { 0.0 };
            Point::new(c(0), c(1), c(2))
        })
        .collect()
}

#[test]
fn distinct_points_below_the_smallest_extent_are_refused_with_the_range_not_as_coincident() {
    for size in [1e-300, 1e-160] {
        let got = ConvexPolyhedron::from_points(&tetrahedron(size, 0.0));
        match got {
            Err(ShapeError::ExtentOutOfRange { extent, min, max }) => {
                let want = size * (3.0 as Real).sqrt();
                assert!(
                    (extent - want).abs() <= 1e-15 * want,
                    "size {size:e}: extent {extent:e}, expected {want:e} (relative tolerance 1e-15)"
                );
                assert_eq!((min, max), (MIN_EXTENT, MAX_EXTENT), "size {size:e}");
            }
            other => {
                panic!("tetrahedron of size {size:e}: expected ExtentOutOfRange, got {other:?}")
            }
        }
    }
}

/// The stated range is the real one: a tetrahedron just inside either end builds, with a positive finite
/// volume and principal moments equal to the unit tetrahedron's scaled by size³ and size⁵.
#[test]
fn tetrahedra_inside_the_stated_extent_range_build_with_finite_mass_properties() {
    let (unit, _) = ConvexPolyhedron::from_points(&tetrahedron(1.0, 0.0)).unwrap();
    let unit = unit.mass_properties().clone();
    for size in [MIN_EXTENT, 1e-3, 1e3, MAX_EXTENT / 2.0] {
        let (p, _) = ConvexPolyhedron::from_points(&tetrahedron(size, 0.0))
            .unwrap_or_else(|e| panic!("tetrahedron of size {size:e}: {e}"));
        let m = p.mass_properties();
        let checks = [
            ("volume", m.volume, unit.volume * size.powi(3)),
            (
                "smallest moment",
                m.principal_moments.min(),
                unit.principal_moments.min() * size.powi(5),
            ),
            (
                "largest moment",
                m.principal_moments.max(),
                unit.principal_moments.max() * size.powi(5),
            ),
        ];
        for (what, got, want) in checks {
            assert!(
                got.is_normal() && (got - want).abs() <= 1e-12 * want,
                "size {size:e}: {what} {got:e}, expected {want:e} (relative tolerance 1e-12)"
            );
        }
    }
}

#[test]
fn a_small_cube_far_from_the_origin_is_refused_with_the_size_it_needs_there() {
    let got = ConvexPolyhedron::from_points(&cube(1e-3, 1e11));
    match got {
        Err(ShapeError::BelowRoundOff {
            extent,
            largest,
            min_extent,
            ..
        }) => {
            assert!(
                extent < min_extent && largest >= 1e11,
                "extent {extent:e}, largest coordinate {largest:e}, stated minimum {min_extent:e}"
            );
            let message = got.unwrap_err().to_string();
            assert!(
                message.contains("nearby origin"),
                "the message says how to fix it: {message}"
            );
        }
        other => panic!("1 mm cube at 1e11 m: expected BelowRoundOff, got {other:?}"),
    }
    // The stated minimum is enough there, and the same cube near the origin (or 1e7 m out) builds.
    let min_extent = match ConvexPolyhedron::from_points(&cube(1e-3, 1e11)) {
        Err(ShapeError::BelowRoundOff { min_extent, .. }) => min_extent,
        other => panic!("expected BelowRoundOff, got {other:?}"),
    };
    let side = 2.0 * min_extent;
    for (side, offset) in [(side, 1e11), (1e-3, 0.0), (1e-3, 1e7)] {
        let built = ConvexPolyhedron::from_points(&cube(side, offset));
        assert!(
            built.as_ref().is_ok_and(|(p, _)| p.num_faces() == 6),
            "cube of side {side:e} at {offset:e}: expected six faces, got {:?}",
            built.map(|(p, _)| p.num_faces())
        );
    }
}

#[test]
fn a_byte_order_mark_before_the_first_contact_pair_is_skipped() {
    let pair = r#"{"id":1,"a":[[0,0,0],[1,0,0],[0,1,0],[0,0,1]],"b":[[0.1,0.1,0.1],[2,0,0],[0,2,0],[0,0,2]]}"#;
    let plain = format!("{pair}\n{pair}\n");
    let marked = format!("\u{feff}{plain}");
    let answer = |input: &str| {
        let mut out = Vec::new();
        let summary = answer_stream(
            input.as_bytes(),
            &mut out,
            &polydem::contact::query_polyhedra,
        )
        .unwrap();
        (summary, String::from_utf8(out).unwrap())
    };
    let (want_summary, want) = answer(&plain);
    let (summary, got) = answer(&marked);
    assert_eq!(want_summary.answered, 2, "plain input: {want}");
    assert_eq!(
        (summary, &got),
        (want_summary, &want),
        "input with a byte-order mark: answers differ from the plain input's"
    );
    // A mark anywhere else is content, and its line an error.
    let (inner, _) = answer(&format!("{pair}\n\u{feff}{pair}\n"));
    assert_eq!(
        (inner.answered, inner.errors),
        (1, 1),
        "a mark at the start of line 2"
    );
}

#[test]
fn scene_and_body_files_with_a_byte_order_mark_load() {
    let dir = std::env::temp_dir().join(format!("polydem_bom_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = r#"
[simulation]
gravity = [0.0, 0.0, -9.81]
end_time = 0.01
output_interval = 0.005
time_step = 1e-5

[[material]]
name = "glass"
density = 2500.0

[[interaction]]
materials = ["glass", "glass"]
law = "linear"
normal_stiffness = 1.0e5
restitution = 0.5
friction = 0.0

[[body_file]]
path = "spheres.csv"
material = "glass"
name_prefix = "s"
"#;
    let write = |name: &str, text: &str| {
        let mut f = std::fs::File::create(dir.join(name)).unwrap();
        f.write_all("\u{feff}".as_bytes()).unwrap();
        f.write_all(text.as_bytes()).unwrap();
    };
    write("scene.toml", scene);
    write("spheres.csv", "x,y,z,radius\n0,0,0,0.01\n1,0,0,0.02\n");
    let sim = polydem::scene::load_scene(&dir.join("scene.toml"));
    std::fs::remove_dir_all(&dir).ok();
    let sim = sim.unwrap_or_else(|e| panic!("scene and body file with a byte-order mark: {e}"));
    assert_eq!(sim.world.bodies().len(), 2, "bodies read from spheres.csv");
}
