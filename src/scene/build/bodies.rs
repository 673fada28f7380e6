//! `[[body]]`: one rigid body per entry, placed by the pose of the shape's own frame and given its initial
//! velocities and motion kind; [`place`] is the placement the body files share.

use std::ops::Range;

use crate::dynamics::{Motion, PrincipalInertia, RigidBody};
use crate::fixed_hash::FixedHashMap;
use crate::math::{Point, Pose, Real, Rotation, Vector};
use crate::shape::Shape;

use super::super::orientation::unit_quaternion;
use super::super::schema::{BodySection, SceneFile};
use super::materials::Materials;
use super::shapes::{volume_and_moments, Shapes};
use super::{Ctx, SceneError};

/// A checked body, before it enters the world.
pub(super) struct SceneBody {
    pub name: String,
    /// Index into [`Shapes::list`].
    pub shape: usize,
    pub material: u32,
    pub body: RigidBody,
    /// The pose of the principal frame in the shape's own frame.
    pub frame: Pose,
    pub track: bool,
    /// The span and field an error of the world about this body names.
    pub origin: (Range<usize>, String),
}

/// The bodies of a scene in file order, and the names taken.
pub(super) struct Bodies {
    pub list: Vec<SceneBody>,
    pub names: FixedHashMap<String, ()>,
}

/// Every `[[body]]`.
pub(super) fn read(
    ctx: &Ctx,
    file: &SceneFile,
    shapes: &Shapes,
    materials: &Materials,
) -> Result<Bodies, SceneError> {
    let mut bodies = Bodies {
        list: Vec::new(),
        names: FixedHashMap::default(),
    };
    for (k, b) in file.bodies.iter().enumerate() {
        let body = read_body(ctx, k, b, shapes, materials, &mut bodies.names)?;
        bodies.list.push(body);
    }
    Ok(bodies)
}

/// One `[[body]]`: its name (unique), shape, material, pose, velocities and motion.
fn read_body(
    ctx: &Ctx,
    k: usize,
    b: &BodySection,
    shapes: &Shapes,
    materials: &Materials,
    names: &mut FixedHashMap<String, ()>,
) -> Result<SceneBody, SceneError> {
    let f = |x: &str| format!("body[{k}].{x}");
    let name = b.name.get_ref().as_str();
    if name.is_empty() || name.contains([',', '"', '\n', '\r']) {
        return Err(ctx.invalid(b.name.span(), f("name"), format!("'{name}' must be non-empty without commas, quotes or line breaks (it is the id column of bodies.csv)")));
    }
    if names.insert(name.to_owned(), ()).is_some() {
        return Err(ctx.invalid(b.name.span(), f("name"), format!("duplicate body '{name}'")));
    }
    let shape_index = shapes.find(b.shape.get_ref().as_str()).ok_or_else(|| {
        ctx.invalid(
            b.shape.span(),
            f("shape"),
            format!("unknown shape '{}'", b.shape.get_ref()),
        )
    })?;
    let mat = materials.id(ctx, &b.material, f("material"))?;
    let position = ctx.vector(&b.position, &f("position"))?;
    let orientation = orientation(ctx, k, b)?;
    let velocity = ctx.vector_or_zero(&b.velocity, &f("velocity"))?;
    let omega = ctx.vector_or_zero(&b.angular_velocity, &f("angular_velocity"))?;
    let motion = motion(ctx, k, b, velocity, omega)?;
    let (shape, frame) = &shapes.list[shape_index];
    let placement = Placement {
        position,
        orientation,
        velocity,
        omega,
        motion,
    };
    let body = place(shape, frame, materials.densities[mat as usize], &placement).map_err(|e| {
        let (span, field) = match e.kind {
            PlaceIssue::Inertia => (b.shape.span(), f("shape")),
            PlaceIssue::Mass => (b.material.span(), f("material")),
            PlaceIssue::AngularMomentum => (
                b.angular_velocity
                    .as_ref()
                    .map(|v| v.span())
                    .unwrap_or_else(|| b.shape.span()),
                f("angular_velocity"),
            ),
        };
        ctx.invalid(span, field, e.message)
    })?;
    Ok(SceneBody {
        name: name.to_owned(),
        shape: shape_index,
        material: mat,
        body,
        frame: *frame,
        track: b.track.unwrap_or(false),
        origin: (b.material.span(), f("material")),
    })
}

/// `orientation` (a unit quaternion, see [`unit_quaternion`]) or `axis_angle`; absent = identity.
fn orientation(ctx: &Ctx, k: usize, b: &BodySection) -> Result<Rotation, SceneError> {
    let f = |x: &str| format!("body[{k}].{x}");
    match (&b.orientation, &b.axis_angle) {
        (Some(_), Some(aa)) => Err(ctx.invalid(
            aa.span(),
            f("axis_angle"),
            "give either orientation or axis_angle, not both",
        )),
        (Some(q), None) => unit_quaternion(*q.get_ref()).map_err(|norm| {
            ctx.invalid(
                q.span(),
                f("orientation"),
                format!("must be a unit quaternion [w, x, y, z], got norm {norm}"),
            )
        }),
        (None, Some(aa)) => Ok(Rotation::from_scaled_axis(
            ctx.vector(aa, &f("axis_angle"))?,
        )),
        (None, None) => Ok(Rotation::identity()),
    }
}

/// `motion`: `"dynamic"` (absent), `"fixed"` or `"prescribed"` (with the body's velocities).
fn motion(
    ctx: &Ctx,
    k: usize,
    b: &BodySection,
    velocity: Vector,
    omega: Vector,
) -> Result<Motion, SceneError> {
    match b.motion.as_ref().map(|m| (m.get_ref().as_str(), m.span())) {
        None | Some(("dynamic", _)) => Ok(Motion::Dynamic),
        Some(("fixed", _)) => Ok(Motion::Fixed),
        Some(("prescribed", _)) => Ok(Motion::Prescribed {
            velocity,
            angular_velocity_world: omega,
        }),
        Some((other, span)) => Err(ctx.invalid(
            span,
            format!("body[{k}].motion"),
            format!("unknown motion '{other}' (expected \"dynamic\", \"fixed\" or \"prescribed\")"),
        )),
    }
}

/// Where and how a body starts: the pose of the shape's own frame, the velocities (world frame), the
/// motion kind.
pub(super) struct Placement {
    /// Where the origin of the shape's own coordinates goes (m).
    pub position: Vector,
    pub orientation: Rotation,
    /// Velocity of the centre of mass (m/s).
    pub velocity: Vector,
    /// Angular velocity (rad/s, world frame).
    pub omega: Vector,
    pub motion: Motion,
}

/// Which quantity of a placed body is invalid.
#[derive(Clone, Copy, Debug)]
pub(super) enum PlaceIssue {
    /// The principal moments (the shape with the density).
    Inertia,
    /// The mass (the shape's volume with the density).
    Mass,
    /// J ω is not finite.
    AngularMomentum,
}

/// A body that cannot be placed: which quantity, and the message.
pub(super) struct PlaceError {
    pub kind: PlaceIssue,
    pub message: String,
}

/// The rigid body of `shape` (principal frame `frame`) of density `density` placed as `p`: its centre at
/// the frame's origin seen from `p.position`, its orientation that of the principal frame; a fixed body
/// keeps no velocity.
pub(super) fn place(
    shape: &Shape,
    frame: &Pose,
    density: Real,
    p: &Placement,
) -> Result<RigidBody, PlaceError> {
    let issue = |kind: PlaceIssue, message: String| PlaceError { kind, message };
    let (volume, moments) = volume_and_moments(shape);
    let inertia = PrincipalInertia::new(moments * density)
        .map_err(|e| issue(PlaceIssue::Inertia, e.to_string()))?;
    let mut body = RigidBody::new_dynamic(Point::origin(), volume * density, inertia)
        .map_err(|e| issue(PlaceIssue::Mass, e.to_string()))?;
    body.position = Point::from(p.position) + p.orientation * frame.translation.vector;
    body.orientation = p.orientation * frame.rotation;
    let fixed = matches!(p.motion, Motion::Fixed);
    body.velocity = if fixed { Vector::zeros() } else { p.velocity };
    body.motion = p.motion;
    if !fixed {
        body.set_angular_velocity(&p.omega);
        // J ω can overflow for a finite but huge ω (or huge moments of inertia).
        if !body.angular_momentum.iter().all(|x| x.is_finite()) {
            return Err(issue(
                PlaceIssue::AngularMomentum,
                format!(
                    "the angular momentum J ω = {:?} is not finite (ω = {:?} rad/s, principal moments {:?} kg·m²)",
                    body.angular_momentum, p.omega, body.inertia.0
                ),
            ));
        }
    }
    Ok(body)
}
