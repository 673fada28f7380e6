//! `[[body_file]]`: bodies from a CSV file ([`crate::scene::body_file`]), named by a prefix and the row's
//! id, all of one material: spheres of their own radius (a sphere table), or the scene's `[[shape]]`s
//! placed by a pose (a shape table), as `[[body]]` places them.

use std::path::{Path, PathBuf};

use crate::dynamics::{Motion, PrincipalInertia, RigidBody};
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::{Shape, Sphere};

use super::super::body_file::{read_body_table, BodyFileError, BodyTable, PoseRow, SphereRow};
use super::super::schema::{BodyFileSection, SceneFile};
use super::bodies::{place, Bodies, PlaceIssue, Placement, SceneBody};
use super::materials::Materials;
use super::shapes::Shapes;
use super::{Ctx, SceneError};

/// One `[[body_file]]` being read, with what its error messages name.
struct Section<'a> {
    ctx: &'a Ctx<'a>,
    k: usize,
    bf: &'a BodyFileSection,
    /// The CSV file, relative paths taken from the scene file's directory.
    csv_path: PathBuf,
    material: u32,
    density: Real,
}

impl Section<'_> {
    fn field(&self, name: &str) -> String {
        format!("body_file[{}].{name}", self.k)
    }

    /// An error of the CSV's content, on the line of `path`.
    fn content(&self, message: String) -> SceneError {
        self.ctx
            .invalid(self.bf.path.span(), self.field("path"), message)
    }

    /// An error of the row on `line` of the CSV, in `column`.
    fn row_error(&self, line: u64, column: &str, message: String) -> SceneError {
        let e = BodyFileError::Invalid {
            path: self.csv_path.clone(),
            line,
            column: column.to_owned(),
            message,
        };
        self.content(e.to_string())
    }

    /// An error of a body's mass or inertia, on the line of `material`.
    fn material_error(&self, message: String) -> SceneError {
        self.ctx
            .invalid(self.bf.material.span(), self.field("material"), message)
    }

    /// A body named `name` joins the scene: its name must be new.
    fn claim(&self, bodies: &mut Bodies, name: &str) -> Result<(), SceneError> {
        if bodies.names.insert(name.to_owned(), ()).is_some() {
            return Err(self.ctx.invalid(
                self.bf.name_prefix.span(),
                self.field("name_prefix"),
                format!("duplicate body '{name}' (from {})", self.csv_path.display()),
            ));
        }
        Ok(())
    }

    /// The scene entry of a body of this file.
    fn body(&self, name: String, shape: usize, body: RigidBody, frame: Pose) -> SceneBody {
        SceneBody {
            name,
            shape,
            material: self.material,
            body,
            frame,
            track: self.bf.track.unwrap_or(false),
            origin: (self.bf.material.span(), self.field("material")),
        }
    }
}

/// Every `[[body_file]]`; a sphere row adds its own shape to `shapes`.
pub(super) fn read(
    ctx: &Ctx,
    file: &SceneFile,
    materials: &Materials,
    shapes: &mut Shapes,
    bodies: &mut Bodies,
) -> Result<(), SceneError> {
    for (k, bf) in file.body_files.iter().enumerate() {
        let material = materials.id(ctx, &bf.material, format!("body_file[{k}].material"))?;
        let relative = Path::new(bf.path.get_ref());
        let csv_path = match ctx.path.parent() {
            Some(dir) if relative.is_relative() => dir.join(relative),
            _ => relative.to_owned(),
        };
        let section = Section {
            ctx,
            k,
            bf,
            csv_path,
            material,
            density: materials.densities[material as usize],
        };
        let table =
            read_body_table(&section.csv_path).map_err(|e| section.content(e.to_string()))?;
        match table {
            BodyTable::Spheres(rows) => {
                let has = rows[0].velocity.is_some();
                let from_file = use_file_velocities(&section, has, "vx, vy, vz")?;
                for row in rows {
                    add_sphere(&section, row, from_file, shapes, bodies)?;
                }
            }
            BodyTable::Poses(rows) => {
                let has = rows[0].velocity.is_some() || rows[0].angular_velocity.is_some();
                let from_file = use_file_velocities(&section, has, "vx, vy, vz or wx, wy, wz")?;
                for row in rows {
                    add_posed(&section, row, from_file, shapes, bodies)?;
                }
            }
        }
    }
    Ok(())
}

/// `velocities`: `"file"` (absent: when the file has them) or `"zero"`; `columns` names the velocity
/// columns of the table.
fn use_file_velocities(
    s: &Section,
    file_has_velocities: bool,
    columns: &str,
) -> Result<bool, SceneError> {
    let Some(v) = &s.bf.velocities else {
        return Ok(true);
    };
    match v.get_ref().as_str() {
        "file" if !file_has_velocities => Err(s.ctx.invalid(
            v.span(),
            s.field("velocities"),
            format!("{} has no {columns} columns", s.csv_path.display()),
        )),
        "file" => Ok(true),
        "zero" => Ok(false),
        other => Err(s.ctx.invalid(
            v.span(),
            s.field("velocities"),
            format!("unknown choice '{other}' (expected \"file\" or \"zero\")"),
        )),
    }
}

/// A sphere row: a dynamic sphere with its own shape, centred at the row's position.
fn add_sphere(
    s: &Section,
    row: SphereRow,
    use_file_velocities: bool,
    shapes: &mut Shapes,
    bodies: &mut Bodies,
) -> Result<(), SceneError> {
    let name = format!("{}{}", s.bf.name_prefix.get_ref(), row.id);
    s.claim(bodies, &name)?;
    let sphere = Sphere::new(row.radius)
        .map_err(|e| s.content(format!("{}: body '{name}': {e}", s.csv_path.display())))?;
    let props = sphere.mass_properties();
    let inertia = PrincipalInertia::new(props.principal_moments * s.density)
        .map_err(|e| s.material_error(e.to_string()))?;
    let mut body =
        RigidBody::new_dynamic(Point::from(row.position), props.volume * s.density, inertia)
            .map_err(|e| s.material_error(e.to_string()))?;
    if use_file_velocities {
        body.velocity = row.velocity.unwrap_or_else(Vector::zeros);
    }
    shapes.list.push((Shape::Sphere(sphere), Pose::identity()));
    bodies
        .list
        .push(s.body(name, shapes.list.len() - 1, body, Pose::identity()));
    Ok(())
}

/// A shape-table row: a dynamic body of the named `[[shape]]`, its own frame placed at the row's pose.
fn add_posed(
    s: &Section,
    row: PoseRow,
    use_file_velocities: bool,
    shapes: &Shapes,
    bodies: &mut Bodies,
) -> Result<(), SceneError> {
    let name = format!("{}{}", s.bf.name_prefix.get_ref(), row.id);
    s.claim(bodies, &name)?;
    let shape_index = shapes.find(&row.shape).ok_or_else(|| {
        s.row_error(
            row.line,
            "shape",
            format!(
                "unknown shape '{}' (not a [[shape]] of the scene)",
                row.shape
            ),
        )
    })?;
    let (shape, frame) = &shapes.list[shape_index];
    let from_file = |v: Option<Vector>| match v {
        Some(v) if use_file_velocities => v,
        _ => Vector::zeros(),
    };
    let placement = Placement {
        position: row.position,
        orientation: row.orientation,
        velocity: from_file(row.velocity),
        omega: from_file(row.angular_velocity),
        motion: Motion::Dynamic,
    };
    let body = place(shape, frame, s.density, &placement).map_err(|e| match e.kind {
        PlaceIssue::AngularMomentum => s.row_error(row.line, "wx, wy, wz", e.message),
        PlaceIssue::Inertia | PlaceIssue::Mass => s.material_error(e.message),
    })?;
    bodies.list.push(s.body(name, shape_index, body, *frame));
    Ok(())
}
