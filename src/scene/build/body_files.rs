//! `[[body_file]]`: bodies from a CSV file ([`crate::scene::body_file`]), named by a prefix and the row's
//! id, all of one material.

use std::path::{Path, PathBuf};

use crate::dynamics::{PrincipalInertia, RigidBody};
use crate::math::{Point, Pose, Vector};
use crate::shape::{Shape, Sphere};

use super::super::body_file::{read_sphere_table, SphereRow};
use super::super::schema::{BodyFileSection, SceneFile};
use super::bodies::{Bodies, SceneBody};
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
        };
        let rows =
            read_sphere_table(&section.csv_path).map_err(|e| section.content(e.to_string()))?;
        let use_file_velocities = use_file_velocities(&section, rows[0].velocity.is_some())?;
        let density = materials.densities[material as usize];
        for row in rows {
            add_sphere(&section, row, density, use_file_velocities, shapes, bodies)?;
        }
    }
    Ok(())
}

/// `velocities`: `"file"` (absent: when the file has them) or `"zero"`.
fn use_file_velocities(s: &Section, file_has_velocities: bool) -> Result<bool, SceneError> {
    let Some(v) = &s.bf.velocities else {
        return Ok(true);
    };
    match v.get_ref().as_str() {
        "file" if !file_has_velocities => Err(s.ctx.invalid(
            v.span(),
            s.field("velocities"),
            format!("{} has no vx, vy, vz columns", s.csv_path.display()),
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
    density: crate::math::Real,
    use_file_velocities: bool,
    shapes: &mut Shapes,
    bodies: &mut Bodies,
) -> Result<(), SceneError> {
    let name = format!("{}{}", s.bf.name_prefix.get_ref(), row.id);
    s.claim(bodies, &name)?;
    let sphere = Sphere::new(row.radius)
        .map_err(|e| s.content(format!("{}: body '{name}': {e}", s.csv_path.display())))?;
    let props = sphere.mass_properties();
    let inertia = PrincipalInertia::new(props.principal_moments * density)
        .map_err(|e| s.material_error(e.to_string()))?;
    let mut body =
        RigidBody::new_dynamic(Point::from(row.position), props.volume * density, inertia)
            .map_err(|e| s.material_error(e.to_string()))?;
    if use_file_velocities {
        body.velocity = row.velocity.unwrap_or_else(Vector::zeros);
    }
    shapes.list.push((Shape::Sphere(sphere), Pose::identity()));
    bodies.list.push(SceneBody {
        name,
        shape: shapes.list.len() - 1,
        material: s.material,
        body,
        frame: Pose::identity(),
        track: s.bf.track.unwrap_or(false),
        origin: (s.bf.material.span(), s.field("material")),
    });
    Ok(())
}
