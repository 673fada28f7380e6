//! The sphere path of stages 4–5: a candidate whose two sides are spheres, or a wall and a sphere, goes
//! from the body positions to the law without the general pair dispatch.
//!
//! Per step the step gathers, once per body, what a sphere contact reads of it ([`SphereBody`]: centre,
//! velocity, angular velocity, radii, length scale, mass, material, whether it is a dynamic sphere) into
//! one compact array, so that a candidate reads two small records instead of two rigid bodies, their
//! shapes and materials; the angular velocity (L/J for a body with equal principal moments when the
//! `isotropic_rotation` skip is on, R J̄⁻¹ Rᵀ L otherwise, as [`super::laws`] takes it) is formed once per
//! body instead of once per contact side. A candidate then takes:
//! - the bounding-sphere rejection (when the skip is on) and the closed forms
//!   [`contact_sphere_sphere`] / [`contact_plane_sphere`], with the same arguments as the general
//!   narrow phase;
//! - for an overlapping pair, the kinematics (v_B − v_A at the contact point, m*, centres) and the model
//!   scaled by √R* from the two radii ([`crate::law::ContactModel::for_contact_radii`]), then the same end of stage 5
//!   as every other pair ([`super::laws::overlap_law`]), the ledger's velocity at the last contact point
//!   also from the gathered records;
//! - for a pair that does not overlap, the general stage 5 ([`super::laws::contact_law`]).
//!
//! Every value is computed by the same operations in the same order as the general path, so the path is
//! exact: bodies, loads, ledger and contact store are the same bits with the `sphere_kernel` skip on or off
//! (`tests/world_sphere_fast_paths.rs`, `tests/world_skips.rs`).

use crate::contact::{
    contact_plane_sphere, contact_sphere_sphere, ContactGeometry, ContactKind, ContactTolerances,
    QueryCounters,
};
use crate::dynamics::body::RigidBody;
use crate::dynamics::rotation::is_isotropic;
use crate::law::{ContactKinematics, ContactModel};
use crate::math::{Point, Real, Vector};
use crate::shape::Shape;
use rayon::prelude::*;

use super::super::contact_store::{ContactKey, ContactState};
use super::super::parallel::Worker;
use super::super::skips;
use super::super::world::{Wall, World};
use super::laws::{contact_law, overlap_law, Evaluated, PairInputs};
use super::params::StepParams;
use super::report::StepError;

/// What a sphere contact reads of one body (gathered once per step by [`gather`]).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct SphereBody {
    position: Point,
    velocity: Vector,
    /// World angular velocity, as the general path takes it (see the module docs); zero for a body that
    /// is not a sphere (never read).
    omega: Vector,
    /// Radius of the sphere (m); zero for another shape.
    radius: Real,
    /// Length scale of the shape (the diameter, m).
    length_scale: Real,
    mass: Real,
    material: u32,
    /// Whether the body's shape is a sphere (only then is the record read).
    sphere: bool,
    dynamic: bool,
}

/// Fills `out` with one [`SphereBody`] per body of `world`; `isotropic` is the `isotropic_rotation` skip.
/// Returns whether some body is a sphere (otherwise the kernel has nothing to do).
pub(super) fn gather(
    world: &World,
    isotropic: bool,
    parallel: bool,
    out: &mut Vec<SphereBody>,
) -> bool {
    out.clear();
    if !world.shapes.iter().any(|s| matches!(s, Shape::Sphere(_))) {
        return false;
    }
    let one = |(i, body): (usize, &RigidBody)| {
        let Shape::Sphere(sphere) = world.shape(i) else {
            return SphereBody::default();
        };
        let omega = if isotropic && is_isotropic(&body.inertia.0) {
            body.angular_momentum / body.inertia.0.x
        } else {
            body.angular_velocity()
        };
        SphereBody {
            position: body.position,
            velocity: body.velocity,
            omega,
            radius: sphere.radius(),
            length_scale: sphere.length_scale(),
            mass: body.mass,
            material: world.material_of[i],
            sphere: true,
            dynamic: body.is_dynamic(),
        }
    };
    // One slot per body, each a function of that body alone: the same slots on any number of threads
    // (an indexed parallel extend keeps the order). On many threads this pass would otherwise be a serial
    // part of every step of a large bed.
    if parallel {
        out.par_extend(world.bodies.par_iter().enumerate().map(one));
    } else {
        out.extend(world.bodies.iter().enumerate().map(one));
    }
    true
}

impl SphereBody {
    /// Velocity (m/s) of the material point at `point` (world).
    #[inline]
    fn velocity_at(&self, point: &Point) -> Vector {
        self.velocity + self.omega.cross(&(point - self.position))
    }

    /// Velocity (m/s) at `point` with the lever arm from the centre `back` seconds earlier (x − back·v):
    /// [`super::step`]'s `PairInputs::relative_velocity` for one side.
    #[inline]
    fn velocity_back_at(&self, point: &Point, back: Real) -> Vector {
        self.velocity_at(&(point + back * self.velocity))
    }
}

/// Stage 4's geometry of the spheres at `xa` and `xb` (radii `ra`, `rb`): the bounding-sphere
/// rejection's when `bounding` (the skip) is on and rejects the pair, else the closed form of
/// [`contact_sphere_sphere`]; counted in `counters`.
#[inline(always)]
pub(in crate::world) fn sphere_pair_geometry(
    xa: &Point,
    ra: Real,
    xb: &Point,
    rb: Real,
    bounding: bool,
    tol: &ContactTolerances,
    counters: &mut QueryCounters,
) -> ContactGeometry {
    let scale = (2.0 * ra).max(2.0 * rb);
    let rejected = bounding
        .then(|| skips::reject_by_bounding_spheres(xa, ra, xb, rb, scale, tol, counters))
        .flatten();
    rejected_or(rejected, counters, |c| {
        c.sphere_sphere += 1;
        contact_sphere_sphere(xa, ra, xb, rb, tol)
    })
}

/// Stage 4's geometry of wall `w` and the sphere at `x` (radius `r`), as [`sphere_pair_geometry`]
/// (the closed form of [`contact_plane_sphere`]).
#[inline(always)]
pub(in crate::world) fn wall_sphere_geometry(
    w: &Wall,
    x: &Point,
    r: Real,
    bounding: bool,
    tol: &ContactTolerances,
    counters: &mut QueryCounters,
) -> ContactGeometry {
    let rejected = bounding
        .then(|| {
            let height = w.signed_distance(x);
            skips::reject_wall_by_bounding_sphere(height, &w.normal_world(), x, r, counters)
        })
        .flatten();
    rejected_or(rejected, counters, |c| {
        c.sphere_plane += 1;
        contact_plane_sphere(&w.pose, w.plane.normal(), w.plane.offset(), x, r, tol)
    })
}

/// A candidate's geometry: the bounding-sphere rejection's when there is one, else the closed form's
/// (`query` counts its kind), recorded in the counters.
#[inline]
fn rejected_or(
    rejected: Option<ContactGeometry>,
    counters: &mut QueryCounters,
    query: impl FnOnce(&mut QueryCounters) -> ContactGeometry,
) -> ContactGeometry {
    rejected.unwrap_or_else(|| {
        let g = query(counters);
        counters.record(&g);
        g
    })
}

/// Stages 4–5 for `key` if both its sides are spheres or a wall and a sphere: `Some` with the result of
/// the stage (written to `state` and `out` as the general path writes them), `None` for any other pair.
/// `previous_point` is the contact point of the pair's last evaluation.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn evaluate(
    params: &StepParams,
    pair: &PairInputs,
    spheres: &[SphereBody],
    key: ContactKey,
    state: &mut ContactState,
    previous_point: &Point,
    out: &mut Evaluated,
    worker: &mut Worker,
) -> Option<Result<(), StepError>> {
    let at = Evaluation {
        params,
        pair,
        previous_point,
    };
    let counters = &mut worker.query;
    match key {
        ContactKey::Body { a, b } => {
            let (sa, sb) = (&spheres[a as usize], &spheres[b as usize]);
            (sa.sphere && sb.sphere).then(|| at.sphere_pair(key, sa, sb, state, out, counters))
        }
        ContactKey::Wall { body, wall } => {
            let s = &spheres[body as usize];
            let w = &pair.world.walls[wall as usize];
            s.sphere
                .then(|| at.sphere_wall(key, w, s, state, out, counters))
        }
    }
}

/// What every sphere pair of a step's evaluation reads: the step's parameters, the pair inputs and the
/// pair's last contact point.
struct Evaluation<'a> {
    params: &'a StepParams,
    pair: &'a PairInputs<'a>,
    previous_point: &'a Point,
}

impl Evaluation<'_> {
    /// [`evaluate`] for a pair of spheres `sa`, `sb`.
    #[inline(always)]
    fn sphere_pair(
        &self,
        key: ContactKey,
        sa: &SphereBody,
        sb: &SphereBody,
        state: &mut ContactState,
        out: &mut Evaluated,
        counters: &mut QueryCounters,
    ) -> Result<(), StepError> {
        let (params, pair, previous_point) = (self.params, self.pair, self.previous_point);
        let (tol, bounding) = (&params.tolerances, params.skips.bounding_spheres);
        let (xa, ra, xb, rb) = (&sa.position, sa.radius, &sb.position, sb.radius);
        state.geometry = sphere_pair_geometry(xa, ra, xb, rb, bounding, tol, counters);
        if state.geometry.kind != ContactKind::Overlap {
            return separated_law(pair, key, state, previous_point, out);
        }
        let model = match pair.model(sa.material, sb.material) {
            Ok(m) => m.for_contact_radii(Some(sa.radius), Some(sb.radius)),
            Err(e) => return Err(e),
        };
        let effective_mass = match (sa.dynamic, sb.dynamic) {
            (true, true) => sa.mass * sb.mass / (sa.mass + sb.mass),
            (true, false) => sa.mass,
            _ => sb.mass,
        };
        let point = &state.geometry.point;
        let kinematics = ContactKinematics {
            relative_velocity: sb.velocity_at(point) - sa.velocity_at(point),
            effective_mass,
            center_a: sa.position,
            center_b: sb.position,
            dt: pair.dt,
        };
        let scale = sa.length_scale.min(sb.length_scale);
        let dt = pair.dt;
        let previous_velocity =
            || sb.velocity_back_at(previous_point, dt) - sa.velocity_back_at(previous_point, dt);
        sphere_overlap_law(
            pair,
            state,
            previous_velocity,
            &model,
            &kinematics,
            scale,
            out,
        );
        Ok(())
    }

    /// [`evaluate`] for wall `w` and sphere `s`.
    #[inline(always)]
    fn sphere_wall(
        &self,
        key: ContactKey,
        w: &Wall,
        s: &SphereBody,
        state: &mut ContactState,
        out: &mut Evaluated,
        counters: &mut QueryCounters,
    ) -> Result<(), StepError> {
        let (params, pair, previous_point) = (self.params, self.pair, self.previous_point);
        let (tol, bounding) = (&params.tolerances, params.skips.bounding_spheres);
        state.geometry = wall_sphere_geometry(w, &s.position, s.radius, bounding, tol, counters);
        if state.geometry.kind != ContactKind::Overlap {
            return separated_law(pair, key, state, previous_point, out);
        }
        let model = match pair.model(w.material, s.material) {
            Ok(m) => m.for_contact_radii(None, Some(s.radius)),
            Err(e) => return Err(e),
        };
        let g = &state.geometry;
        let kinematics = ContactKinematics {
            relative_velocity: s.velocity_at(&g.point) - w.velocity,
            effective_mass: s.mass,
            center_a: g.point_a,
            center_b: s.position,
            dt: pair.dt,
        };
        let dt = pair.dt;
        let previous_velocity = || s.velocity_back_at(previous_point, dt) - w.velocity;
        let scale = s.length_scale;
        sphere_overlap_law(
            pair,
            state,
            previous_velocity,
            &model,
            &kinematics,
            scale,
            out,
        );
        Ok(())
    }
}

/// Stage 5 for a sphere candidate that does not overlap: [`contact_law`]'s answer. Without the ledger, or
/// when the pair kept no force from its last evaluation (it was already apart: the usual case of a
/// candidate in the skin), there is no release to book, and what the general stage writes is the cleared
/// history and forces and a slot with no force and no work; those are written directly (the same values).
#[inline(always)]
fn separated_law(
    pair: &PairInputs,
    key: ContactKey,
    state: &mut ContactState,
    previous_point: &Point,
    out: &mut Evaluated,
) -> Result<(), StepError> {
    let stale = state.damping_force != Vector::zeros()
        || (state.history.stiffness != 0.0 && state.history.displacement != Vector::zeros());
    if pair.ledger && stale {
        return contact_law(pair, key, state, previous_point, out);
    }
    state.history = Default::default();
    state.force_on_b = Vector::zeros();
    state.damping_force = Vector::zeros();
    out.clear_separated();
    Ok(())
}

/// The end of stage 5 for an overlapping sphere candidate: [`overlap_law`] with the ledger on, else
/// [`lean_overlap_law`] (arguments as [`overlap_law`]'s).
#[inline(always)]
fn sphere_overlap_law(
    pair: &PairInputs,
    state: &mut ContactState,
    previous_velocity: impl FnOnce() -> Vector,
    model: &ContactModel,
    kinematics: &ContactKinematics,
    scale: Real,
    out: &mut Evaluated,
) {
    if pair.ledger {
        overlap_law(
            pair,
            state,
            previous_velocity,
            model,
            kinematics,
            scale,
            out,
        );
    } else {
        lean_overlap_law(state, model, kinematics, scale, out);
    }
}

/// The end of stage 5 for an overlapping sphere candidate when the ledger is off: [`overlap_law`] without
/// its ledger branch (the work slot is zero there too), with the law inlined
/// ([`ContactModel::evaluate_inlined`]: the same operations, so the same bits) so that the terms only the
/// ledger reads (friction and stiffness work, dissipated powers, the rotated previous spring) are not
/// computed.
#[inline(always)]
fn lean_overlap_law(
    state: &mut ContactState,
    model: &ContactModel,
    kinematics: &ContactKinematics,
    scale: Real,
    out: &mut Evaluated,
) {
    let ContactState {
        geometry: g,
        history,
        force_on_b,
        damping_force,
        ..
    } = state;
    let response = model.evaluate_inlined(g, kinematics, history);
    *force_on_b = response.force_on_b;
    *damping_force = response.damping_force;
    out.set_overlapping(&response, g.depth, g.depth / scale);
}
