//! The VTK surfaces series: a body of a shape other than a polyhedron or a sphere (an ellipsoid) is written
//! as its `ConvexShape::surface_mesh` in `surfaces.pvd`, placed by the body's pose, with the polyhedra's
//! cells and fields; a world without such bodies writes no surfaces series.

use std::path::PathBuf;

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::io::vtk::{SeriesKind, VtkFormat, VtkWriter};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::surface_mesh::{SURFACE_LATITUDE_BANDS, SURFACE_MERIDIANS};
use polydem::shape::{Shape, Sphere};
use polydem::world::{MaterialTable, World};

fn temp_dir(case: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "polydem-vtk-surfaces-{}-{case}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn world_with(shape: Shape, position: Point, orientation: Rotation) -> World {
    let mut materials = MaterialTable::default();
    let m = materials.add_material("m");
    materials.set_model(
        m,
        m,
        ContactModel {
            normal: NormalLaw::linear(1e5).expect("stiffness"),
            damping: DampingLaw::None,
            tangential: TangentialLaw::None,
        },
    );
    let mut world = World::new(Vector::zeros(), materials, 0.01);
    let id = world.add_shape(shape);
    let inertia = PrincipalInertia::new(Vector::repeat(1.0)).expect("inertia");
    let mut body = RigidBody::new_dynamic(position, 1.0, inertia).expect("body");
    body.orientation = orientation;
    world.add_body("e", id, 0, body).expect("body");
    world
}

/// The numbers of an ASCII `DataArray` named `name`.
fn ascii_array(text: &str, name: &str) -> Vec<Real> {
    let start = text.find(&format!("Name=\"{name}\"")).expect("array");
    let body = &text[start..];
    let open = body.find('>').expect("tag end") + 1;
    let close = body.find("</DataArray>").expect("array end");
    body[open..close]
        .split_whitespace()
        .map(|x| x.parse().expect("number"))
        .collect()
}

#[test]
fn an_ellipsoid_is_written_as_its_surface_mesh() {
    let axes = (0.3, 0.2, 0.1);
    let pose = Pose::from_parts(
        Vector::new(1.0, 2.0, 3.0).into(),
        Rotation::from_euler_angles(0.3, -0.4, 0.5),
    );
    let world = world_with(
        Shape::ellipsoid(axes.0, axes.1, axes.2).expect("ellipsoid"),
        Point::from(pose.translation.vector),
        pose.rotation,
    );
    let dir = temp_dir("ellipsoid");
    let mut writer = VtkWriter::new(&dir, &world, VtkFormat::Ascii).expect("writer");
    assert_eq!(writer.kinds(), vec![SeriesKind::Surfaces]);
    writer.write_frame(&world).expect("frame");
    let text = std::fs::read_to_string(dir.join("vtk/surfaces_000000000.vtu")).expect("frame file");
    let points = 2 + (SURFACE_LATITUDE_BANDS - 1) * SURFACE_MERIDIANS;
    let cells = 2 * SURFACE_MERIDIANS * (SURFACE_LATITUDE_BANDS - 1);
    let header = format!("NumberOfPoints=\"{points}\" NumberOfCells=\"{cells}\"");
    assert!(
        text.contains(&header),
        "expected {header} in the piece header"
    );
    // Every vertex lies on the placed ellipsoid: |D⁻¹ pose⁻¹ x| = 1.
    let coords = ascii_array(&text, "Points");
    assert_eq!(coords.len(), 3 * points);
    for p in coords.chunks(3) {
        let local = pose.inverse() * Point::new(p[0], p[1], p[2]);
        let r = Vector::new(local.x / axes.0, local.y / axes.1, local.z / axes.2).norm();
        assert!(
            (r - 1.0).abs() <= 1e-14,
            "vertex {p:?}: |D⁻¹ x| = {r}, expected 1"
        );
    }
    assert!(dir.join("surfaces.pvd").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_world_of_spheres_writes_no_surfaces_series() {
    let world = world_with(
        Shape::Sphere(Sphere::new(0.5).expect("sphere")),
        Point::origin(),
        Rotation::identity(),
    );
    let dir = temp_dir("spheres");
    let writer = VtkWriter::new(&dir, &world, VtkFormat::Ascii).expect("writer");
    assert_eq!(writer.kinds(), vec![SeriesKind::Spheres]);
    let _ = std::fs::remove_dir_all(&dir);
}
