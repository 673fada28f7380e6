//! The checked parts of a scene put into a [`World`]: shapes, bodies in file order (the tracked ones
//! noted), walls.

use std::ops::Range;

use crate::math::{Pose, Real, Vector};
use crate::world::{MaterialTable, Wall, World};

use super::bodies::Bodies;
use super::shapes::Shapes;
use super::{Ctx, SceneError};

/// The world of a scene and what the [`super::Simulation`] keeps about its bodies.
pub(super) struct Assembled {
    pub world: World,
    pub tracked: Vec<usize>,
    pub frames: Vec<Pose>,
}

/// Adds every shape, body and wall to a new world.
pub(super) fn world(
    ctx: &Ctx,
    gravity: Vector,
    materials: MaterialTable,
    skin: Real,
    shapes: Shapes,
    bodies: Bodies,
    walls: Vec<(Range<usize>, Wall)>,
) -> Result<Assembled, SceneError> {
    let mut world = World::new(gravity, materials, skin);
    let shape_index_in_world: Vec<u32> = shapes
        .list
        .iter()
        .map(|(s, _)| world.add_shape(s.clone()))
        .collect();
    let mut tracked = Vec::new();
    let mut frames = Vec::new();
    for b in bodies.list {
        let i = world
            .add_body(&b.name, shape_index_in_world[b.shape], b.material, b.body)
            .map_err(|e| {
                let (span, field) = b.origin.clone();
                ctx.invalid(span, field, e.to_string())
            })?;
        frames.push(b.frame);
        if b.track {
            tracked.push(i as usize);
        }
    }
    for (k, (span, wall)) in walls.into_iter().enumerate() {
        world
            .add_wall(wall)
            .map_err(|e| ctx.invalid(span, format!("wall[{k}]"), e.to_string()))?;
    }
    Ok(Assembled {
        world,
        tracked,
        frames,
    })
}
