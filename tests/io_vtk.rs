//! VTK output: the frames parse back with an independent VTK reader (vtkio), the point and face
//! counts are those of the shapes, every vertex is the world pose of the shape's vertex (to 1e-12 of the
//! body size; the ASCII numbers are round-trip exact, so in practice to the bit), the per-body fields are
//! the world's values, the walls are drawn on their planes, and the `.pvd` collections list every frame
//! with its time.

use std::path::{Path, PathBuf};

use polydem::io::vtk::{
    VtkCompression, VtkEncoding, VtkFormat, VtkPrecision, VtkWriter, VTK_POLYGON, VTK_VERTEX,
};
use polydem::math::{Point, Vector};
use polydem::scene::{parse_scene, Simulation};
use polydem::shape::Shape;
use vtkio::model::{Attribute, DataSet, Piece, UnstructuredGridPiece, VertexNumbers};

const SPHERES: &str = r#"
[[shape]]
name = "ball"
kind = "sphere"
radius = 0.02

[[body]]
name = "s0"
shape = "ball"
material = "rock"
position = [-0.05, 0.05, 0.13]
velocity = [0.3, 0.0, -0.5]
angular_velocity = [1.0, 2.0, 3.0]

[[body]]
name = "s1"
shape = "ball"
material = "rock"
position = [0.05, -0.05, 0.13]
"#;

fn scene() -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/settling_box.toml");
    let text = std::fs::read_to_string(&path).expect("settling_box.toml");
    parse_scene(&format!("{text}\n{SPHERES}"), &path).expect("scene")
}

fn temp_dir(case: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem-io-vtk-{}-{case}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn piece(path: &Path) -> UnstructuredGridPiece {
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    match vtk.data {
        DataSet::UnstructuredGrid { mut pieces, .. } => {
            assert_eq!(pieces.len(), 1, "{}: one piece", path.display());
            match pieces.remove(0) {
                Piece::Inline(p) => *p,
                _ => panic!("{}: piece not inline", path.display()),
            }
        }
        other => panic!("{}: not an unstructured grid: {other:?}", path.display()),
    }
}

fn array<T: vtkio::model::Scalar>(attrs: &[Attribute], name: &str) -> Vec<T> {
    for a in attrs {
        if let Attribute::DataArray(d) = a {
            if d.name == name {
                return d.data.cast_into::<T>().expect("numeric array");
            }
        }
    }
    panic!("no array '{name}'");
}

fn connectivity(p: &UnstructuredGridPiece) -> (Vec<u64>, Vec<u64>) {
    match &p.cells.cell_verts {
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => (connectivity.clone(), offsets.clone()),
        VertexNumbers::Legacy { .. } => panic!("XML cells expected"),
    }
}

/// Checks a vector read back: within 1e-12 × `scale` for Float64 frames; for Float32 frames (`rounding` =
/// 2^-24, the relative error of rounding to the nearest f32) each component may further differ by
/// `rounding` × its magnitude (plus f32's smallest normal, for values that underflow).
fn close(rounding: f64, label: &str, got: &[f64], expected: &Vector, scale: f64) {
    let got = Vector::new(got[0], got[1], got[2]);
    let floor = if rounding > 0.0 {
        f32::MIN_POSITIVE as f64
    } else {
        0.0
    };
    for k in 0..3 {
        let tolerance = 1e-12 * scale + rounding * expected[k].abs() + floor;
        assert!(
            (got[k] - expected[k]).abs() <= tolerance,
            "{label}: read {got:?}, expected {expected:?}, component {k} off by {:e}, tolerance {tolerance:e} \
             (1e-12 × {scale} + {rounding:e} × |expected|)",
            (got[k] - expected[k]).abs()
        );
    }
}

#[test]
fn binary_frames_parse_back_with_the_world_geometry_and_fields() {
    frames_parse_back_with_the_world_geometry_and_fields(VtkFormat::Binary.into());
}

#[test]
fn ascii_frames_parse_back_with_the_world_geometry_and_fields() {
    frames_parse_back_with_the_world_geometry_and_fields(VtkFormat::Ascii.into());
}

#[test]
fn uncompressed_binary_frames_parse_back_exactly() {
    frames_parse_back_with_the_world_geometry_and_fields(VtkEncoding {
        compression: VtkCompression::None,
        ..VtkEncoding::default()
    });
}

#[test]
fn float32_frames_parse_back_within_f32_rounding() {
    for encoding in [
        VtkEncoding {
            precision: VtkPrecision::Float32,
            ..VtkEncoding::default()
        },
        VtkEncoding {
            precision: VtkPrecision::Float32,
            compression: VtkCompression::None,
            ..VtkEncoding::default()
        },
        VtkEncoding {
            precision: VtkPrecision::Float32,
            ..VtkFormat::Ascii.into()
        },
    ] {
        frames_parse_back_with_the_world_geometry_and_fields(encoding);
    }
}

#[test]
fn compressed_ascii_is_refused() {
    let sim = scene();
    let dir = temp_dir("compressed-ascii");
    let err = VtkWriter::new(
        &dir,
        &sim.world,
        VtkEncoding {
            format: VtkFormat::Ascii,
            compression: VtkCompression::Zlib,
            ..VtkEncoding::default()
        },
    )
    .expect_err("compressed ASCII must be refused");
    assert!(err.to_string().contains("binary format only"), "{err}");
}

fn frames_parse_back_with_the_world_geometry_and_fields(encoding: VtkEncoding) {
    let rounding = match encoding.precision {
        VtkPrecision::Float64 => 0.0,
        VtkPrecision::Float32 => f64::powi(2.0, -24),
    };
    let close = |label: &str, got: &[f64], expected: &Vector, scale: f64| {
        close(rounding, label, got, expected, scale)
    };
    let mut sim = scene();
    let dir = temp_dir(&format!(
        "frames-{:?}-{:?}-{:?}",
        encoding.format, encoding.precision, encoding.compression
    ));
    let mut writer = VtkWriter::new(&dir, &sim.world, encoding).expect("writer");
    let first = std::fs::read_to_string({
        writer.write_frame(&sim.world).expect("frame at t = 0");
        dir.join("vtk/polyhedra_000000000.vtu")
    })
    .unwrap();
    let expected_format = match encoding.format {
        VtkFormat::Ascii => "format=\"ascii\"",
        VtkFormat::Binary => "format=\"binary\"",
    };
    assert!(first.contains(expected_format), "{encoding:?} frame");
    let expected_type = match encoding.precision {
        VtkPrecision::Float64 => "type=\"Float64\" Name=\"Points\"",
        VtkPrecision::Float32 => "type=\"Float32\" Name=\"Points\"",
    };
    assert!(
        first.contains(expected_type),
        "{encoding:?} frame: {expected_type}"
    );
    assert_eq!(
        first.contains("compressor=\"vtkZLibDataCompressor\""),
        encoding.compression == VtkCompression::Zlib,
        "{encoding:?} frame: compressor attribute"
    );
    sim.steps = 8000;
    sim.run(|_| Ok(()), |_, _| Ok(())).expect("run");
    writer
        .write_frame(&sim.world)
        .expect("frame after 8000 steps");
    let world = &sim.world;
    let step = world.step_index();

    // Polyhedra: counts, faces, coordinates, fields.
    let p = piece(&dir.join(format!("vtk/polyhedra_{step:09}.vtu")));
    let bodies: Vec<usize> = (0..world.bodies().len())
        .filter(|&i| matches!(world.shape(i), Shape::Polyhedron(_)))
        .collect();
    assert_eq!(bodies.len(), 20);
    let expected_points: usize = bodies
        .iter()
        .map(|&i| match world.shape(i) {
            Shape::Polyhedron(p) => p.vertices().len(),
            _ => 0,
        })
        .sum();
    assert_eq!(p.num_points(), expected_points, "points = Σ vertices");
    let points: Vec<f64> = p.points.cast_into().unwrap();
    let (conn, offsets) = connectivity(&p);
    let cell_body: Vec<i64> = array(&p.data.cell, "body");
    let velocity: Vec<f64> = array(&p.data.cell, "velocity");
    let omega: Vec<f64> = array(&p.data.cell, "angular_velocity");
    let force: Vec<f64> = array(&p.data.cell, "contact_force");
    let point_velocity: Vec<f64> = array(&p.data.point, "point_velocity");
    let (mut base, mut cell, mut start) = (0usize, 0usize, 0usize);
    let mut nonzero_forces = 0;
    for &i in &bodies {
        let Shape::Polyhedron(poly) = world.shape(i) else {
            unreachable!()
        };
        let pose = world.pose(i);
        let size = world.length_scale(i);
        let body = &world.bodies()[i];
        for (v, local) in poly.vertices().iter().enumerate() {
            let k = base + v;
            let expected = pose * local;
            close(
                &format!("body {i} vertex {v}"),
                &points[3 * k..3 * k + 3],
                &expected.coords,
                size,
            );
            close(
                &format!("body {i} vertex {v} point_velocity"),
                &point_velocity[3 * k..3 * k + 3],
                &body.velocity_at(&expected),
                body.velocity.norm().max(1e-300),
            );
        }
        for f in 0..poly.num_faces() {
            let end = offsets[cell] as usize;
            let face: Vec<u64> = poly
                .face_vertices(f)
                .iter()
                .map(|&v| (base + v as usize) as u64)
                .collect();
            assert_eq!(&conn[start..end], face.as_slice(), "body {i} face {f}");
            assert_eq!(cell_body[cell], i as i64);
            close(
                &format!("body {i} velocity"),
                &velocity[3 * cell..3 * cell + 3],
                &body.velocity,
                body.velocity.norm(),
            );
            close(
                &format!("body {i} angular velocity"),
                &omega[3 * cell..3 * cell + 3],
                &body.angular_velocity(),
                body.angular_velocity().norm(),
            );
            close(
                &format!("body {i} contact force"),
                &force[3 * cell..3 * cell + 3],
                &world.loads().forces()[i],
                world.loads().forces()[i].norm(),
            );
            start = end;
            cell += 1;
        }
        if world.loads().forces()[i].norm() > 0.0 {
            nonzero_forces += 1;
        }
        base += poly.vertices().len();
    }
    assert_eq!(p.cells.types.len(), cell, "cells = Σ faces");
    assert!(
        p.cells.types.iter().all(|t| *t as u8 == VTK_POLYGON),
        "all cells are polygons"
    );
    assert!(
        nonzero_forces >= 10,
        "only {nonzero_forces} of 20 rocks carry a contact force after 8000 steps: the test would not \
         check the force field"
    );

    // Spheres: centres and radii.
    let s = piece(&dir.join(format!("vtk/spheres_{step:09}.vtu")));
    assert_eq!(s.num_points(), 2);
    assert!(s.cells.types.iter().all(|t| *t as u8 == VTK_VERTEX));
    let centres: Vec<f64> = s.points.cast_into().unwrap();
    let radius: Vec<f64> = array(&s.data.point, "radius");
    let diameter: Vec<f64> = array(&s.data.point, "diameter");
    let sphere_omega: Vec<f64> = array(&s.data.point, "angular_velocity");
    for (k, i) in [20usize, 21].into_iter().enumerate() {
        let b = &world.bodies()[i];
        close(
            &format!("sphere {i} centre"),
            &centres[3 * k..3 * k + 3],
            &b.position.coords,
            0.04,
        );
        close(
            &format!("sphere {i} angular velocity"),
            &sphere_omega[3 * k..3 * k + 3],
            &b.angular_velocity(),
            b.angular_velocity().norm().max(1e-300),
        );
        let stored = |x: f64| if rounding > 0.0 { x as f32 as f64 } else { x };
        assert_eq!(
            (radius[k], diameter[k]),
            (stored(0.02), stored(0.04)),
            "sphere {i}"
        );
    }

    // Walls: each polygon on its plane, on the free side of the other walls, force as in the world.
    let w = piece(&dir.join(format!("vtk/walls_{step:09}.vtu")));
    assert_eq!(w.cells.types.len(), world.walls().len());
    let wall_points: Vec<f64> = w.points.cast_into().unwrap();
    let (conn, offsets) = connectivity(&w);
    let wall_force: Vec<f64> = array(&w.data.cell, "contact_force");
    let mut start = 0;
    for (k, wall) in world.walls().iter().enumerate() {
        let end = offsets[k] as usize;
        assert!(
            end - start >= 3,
            "wall {k} polygon has {} points",
            end - start
        );
        for &v in &conn[start..end] {
            let v = v as usize;
            let x = Point::new(
                wall_points[3 * v],
                wall_points[3 * v + 1],
                wall_points[3 * v + 2],
            );
            // Float32 frames move each coordinate by up to 2^-24 of its magnitude.
            let tolerance = 1e-12 + 2.0 * rounding * x.coords.norm();
            let d = wall.signed_distance(&x);
            assert!(
                d.abs() <= tolerance,
                "wall {k} vertex {x:?} at distance {d} from its plane, tolerance {tolerance:e}"
            );
            for (j, other) in world.walls().iter().enumerate() {
                let dj = other.signed_distance(&x);
                assert!(
                    dj >= -tolerance,
                    "wall {k} vertex {x:?} lies behind wall {j} by {dj}, tolerance {tolerance:e}"
                );
            }
        }
        close(
            &format!("wall {k} force"),
            &wall_force[3 * k..3 * k + 3],
            &world.loads().wall_forces()[k],
            world.loads().wall_forces()[k].norm(),
        );
        start = end;
    }

    // The collections: two frames each, at t = 0 and the current time, files present.
    for series in ["polyhedra", "spheres", "walls"] {
        let pvd = dir.join(format!("{series}.pvd"));
        let text = std::fs::read_to_string(&pvd).expect("pvd");
        let doc = roxmltree::Document::parse(&text).expect("pvd is XML");
        let root = doc.root_element();
        assert_eq!(root.attribute("type"), Some("Collection"));
        let sets: Vec<_> = root
            .descendants()
            .filter(|n| n.has_tag_name("DataSet"))
            .collect();
        assert_eq!(sets.len(), 2, "{series}.pvd entries");
        let times: Vec<f64> = sets
            .iter()
            .map(|n| n.attribute("timestep").unwrap().parse().unwrap())
            .collect();
        assert_eq!(times, vec![0.0, world.time()], "{series}.pvd times");
        for n in &sets {
            let file = dir.join(n.attribute("file").unwrap());
            assert!(file.exists(), "{} listed in {series}.pvd", file.display());
        }
    }
    assert_eq!(writer.frames_written, 2);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_world_without_spheres_or_walls_writes_only_the_polyhedra_series() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_polyhedra_elastic.toml");
    let sim = polydem::scene::load_scene(&path).unwrap();
    let dir = temp_dir("only_polyhedra");
    let mut writer = VtkWriter::new(&dir, &sim.world, VtkFormat::Ascii).unwrap();
    writer.write_frame(&sim.world).unwrap();
    assert!(dir.join("polyhedra.pvd").exists());
    assert!(!dir.join("spheres.pvd").exists() && !dir.join("walls.pvd").exists());
    let p = piece(&dir.join("vtk/polyhedra_000000000.vtu"));
    assert_eq!(p.cells.types.len(), {
        let faces = |i: usize| match sim.world.shape(i) {
            Shape::Polyhedron(p) => p.num_faces(),
            _ => 0,
        };
        faces(0) + faces(1)
    });
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `(time, file)` entries of a `.pvd`, read with an XML parser independent of the writer's.
fn pvd_entries(path: &Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let doc = roxmltree::Document::parse(&text).expect("pvd is XML");
    doc.root_element()
        .descendants()
        .filter(|n| n.has_tag_name("DataSet"))
        .map(|n| {
            (
                n.attribute("timestep").unwrap().parse().unwrap(),
                n.attribute("file").unwrap().to_owned(),
            )
        })
        .collect()
}

#[test]
fn a_restarted_run_continues_the_series_of_the_earlier_run() {
    // The earlier run: frames at steps 0, 100 and 200.
    let dir = temp_dir("resume");
    let mut straight = scene();
    let mut writer = VtkWriter::new(&dir, &straight.world, VtkFormat::Binary).unwrap();
    let mut frames = Vec::new();
    for target in [0u64, 100, 200] {
        straight.steps = target;
        straight.run(|_| Ok(()), |_, _| Ok(())).expect("run");
        writer.write_frame(&straight.world).unwrap();
        frames.push((
            straight.world.time(),
            format!("vtk/spheres_{target:09}.vtu"),
        ));
    }
    assert_eq!(pvd_entries(&dir.join("spheres.pvd")), frames);

    // A restart from step 100 (the same state, reached again) keeps frame 0, rewrites 100 and 200.
    let mut restarted = scene();
    restarted.steps = 100;
    restarted.run(|_| Ok(()), |_, _| Ok(())).expect("run");
    let mut resumed = VtkWriter::resume(&dir, &restarted.world, VtkFormat::Binary).unwrap();
    resumed.write_frame(&restarted.world).unwrap();
    assert_eq!(
        pvd_entries(&dir.join("spheres.pvd")),
        frames[..2].to_vec(),
        "after the restart's first frame: the earlier frame 0, then the restart's frame 100"
    );
    restarted.steps = 200;
    restarted.run(|_| Ok(()), |_, _| Ok(())).expect("run");
    resumed.write_frame(&restarted.world).unwrap();
    for series in ["polyhedra", "spheres", "walls"] {
        let entries = pvd_entries(&dir.join(format!("{series}.pvd")));
        let times: Vec<f64> = entries.iter().map(|(t, _)| *t).collect();
        let expected: Vec<f64> = frames.iter().map(|(t, _)| *t).collect();
        assert_eq!(times, expected, "{series}.pvd times after the restart");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_restart_beside_a_foreign_pvd_is_refused_with_file_and_line() {
    let dir = temp_dir("resume-foreign");
    let sim = scene();
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("walls.pvd"),
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n\
         <DataSet timestep=\"soon\" file=\"vtk/walls_000000010.vtu\"/>\n</Collection>\n</VTKFile>\n",
    )
    .unwrap();
    let err = VtkWriter::resume(&dir, &sim.world, VtkFormat::Binary).expect_err("foreign .pvd");
    let message = err.to_string();
    assert!(
        message.contains("walls.pvd:4") && message.contains("soon"),
        "error should name the file, line 4 and the bad timestep: {message}"
    );
    std::fs::write(dir.join("walls.pvd"), "not xml at all\n").unwrap();
    let err = VtkWriter::resume(&dir, &sim.world, VtkFormat::Binary).expect_err("not a .pvd");
    assert!(err.to_string().contains("walls.pvd:1"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
