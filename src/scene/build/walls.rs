//! `[[wall]]` (a half-space behind a plane) and `[[box]]` (an axis-aligned box of inward-facing walls, one
//! per closed face).

use std::ops::Range;

use crate::math::{Pose, Rotation, Vector};
use crate::shape::Plane;
use crate::world::Wall;

use super::super::schema::{BoxSection, SceneFile, WallSection};
use super::materials::Materials;
use super::{Ctx, SceneError};

/// The faces of a box, in the order their walls are added.
const FACES: [&str; 6] = ["x-", "x+", "y-", "y+", "z-", "z+"];

/// The walls of every `[[wall]]` and then every `[[box]]`, each with the span an error of the world about
/// it names.
pub(super) fn read(
    ctx: &Ctx,
    file: &SceneFile,
    materials: &Materials,
) -> Result<Vec<(Range<usize>, Wall)>, SceneError> {
    let mut walls = Vec::new();
    for (k, w) in file.walls.iter().enumerate() {
        walls.push((w.name.span(), wall(ctx, k, w, materials)?));
    }
    for (k, bx) in file.boxes.iter().enumerate() {
        box_walls(ctx, k, bx, materials, &mut walls)?;
    }
    Ok(walls)
}

/// One `[[wall]]`.
fn wall(ctx: &Ctx, k: usize, w: &WallSection, materials: &Materials) -> Result<Wall, SceneError> {
    let f = |x: &str| format!("wall[{k}].{x}");
    let material = materials.id(ctx, &w.material, f("material"))?;
    let point = ctx.vector(&w.point, &f("point"))?;
    let normal = ctx.vector(&w.normal, &f("normal"))?;
    let plane = Plane::new(normal, 0.0)
        .map_err(|e| ctx.invalid(w.normal.span(), f("normal"), e.to_string()))?;
    let velocity = ctx.vector_or_zero(&w.velocity, &f("velocity"))?;
    Ok(Wall {
        name: w.name.get_ref().clone(),
        plane,
        pose: Pose::from_parts(point.into(), Rotation::identity()),
        velocity,
        material,
    })
}

/// One `[[box]]`: a wall per face not open, named `BOX.FACE`, facing inwards.
fn box_walls(
    ctx: &Ctx,
    k: usize,
    bx: &BoxSection,
    materials: &Materials,
    walls: &mut Vec<(Range<usize>, Wall)>,
) -> Result<(), SceneError> {
    let f = |x: &str| format!("box[{k}].{x}");
    let material = materials.id(ctx, &bx.material, f("material"))?;
    let lo = ctx.vector(&bx.min, &f("min"))?;
    let hi = ctx.vector(&bx.max, &f("max"))?;
    if (0..3).any(|i| hi[i] <= lo[i]) {
        return Err(ctx.invalid(
            bx.max.span(),
            f("max"),
            format!(
                "must exceed min in every coordinate, got min {:?}, max {:?}",
                bx.min.get_ref(),
                bx.max.get_ref()
            ),
        ));
    }
    let open: Vec<String> = match &bx.open {
        Some(o) => {
            for face in o.get_ref() {
                check_face(ctx, face, o.span(), f("open"))?;
            }
            o.get_ref().clone()
        }
        None => Vec::new(),
    };
    let moving = moving_face(ctx, k, bx, &open)?;
    for (j, face) in FACES.iter().enumerate() {
        if open.iter().any(|o| o == face) {
            continue;
        }
        let axis = j / 2;
        let upper = j % 2 == 1;
        let mut normal = Vector::zeros();
        normal[axis] = if upper { -1.0 } else { 1.0 };
        let point = if upper { hi } else { lo };
        let plane = Plane::new(normal, 0.0)
            .map_err(|e| ctx.invalid(bx.min.span(), f("min"), e.to_string()))?;
        let velocity = match &moving {
            Some((m, v)) if m == face => *v,
            _ => Vector::zeros(),
        };
        walls.push((
            bx.name.span(),
            Wall {
                name: format!("{}.{face}", bx.name.get_ref()),
                plane,
                pose: Pose::from_parts(point.into(), Rotation::identity()),
                velocity,
                material,
            },
        ));
    }
    Ok(())
}

/// A face name must be one of [`FACES`].
fn check_face(ctx: &Ctx, name: &str, span: Range<usize>, field: String) -> Result<(), SceneError> {
    if FACES.contains(&name) {
        Ok(())
    } else {
        Err(ctx.invalid(
            span,
            field,
            format!("unknown face '{name}' (expected one of {FACES:?})"),
        ))
    }
}

/// `moving_face` and its `velocity`: both or neither, on a closed face.
fn moving_face(
    ctx: &Ctx,
    k: usize,
    bx: &BoxSection,
    open: &[String],
) -> Result<Option<(String, Vector)>, SceneError> {
    let f = |x: &str| format!("box[{k}].{x}");
    match (&bx.moving_face, &bx.velocity) {
        (None, None) => Ok(None),
        (Some(face), Some(v)) => {
            check_face(ctx, face.get_ref(), face.span(), f("moving_face"))?;
            if open.contains(face.get_ref()) {
                return Err(ctx.invalid(
                    face.span(),
                    f("moving_face"),
                    format!("face '{}' is open", face.get_ref()),
                ));
            }
            Ok(Some((
                face.get_ref().clone(),
                ctx.vector(v, &f("velocity"))?,
            )))
        }
        (Some(face), None) => Err(ctx.invalid(
            face.span(),
            f("velocity"),
            "a moving_face needs a velocity (m/s)",
        )),
        (None, Some(v)) => Err(ctx.invalid(
            v.span(),
            f("moving_face"),
            "a velocity needs the moving_face it belongs to",
        )),
    }
}
