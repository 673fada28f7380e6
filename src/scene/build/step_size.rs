//! `simulation.time_step` or `simulation.steps_per_contact`: the step given and checked against the
//! stability limit, or derived from the shortest contact time ([`crate::scene::time_step`] has the
//! physics), from the lightest dynamic body of each material and the laws of the pairs that can meet.

use std::ops::Range;

use crate::math::Real;
use crate::world::{MaterialTable, Wall};

use super::super::schema::SimulationSection;
use super::super::time_step::{
    contact_time_and_limit, pair_estimates, BodyFacts, TimeStepInfo, TimeStepIssue,
};
use super::bodies::Bodies;
use super::shapes::{bounding_radius, Shapes};
use super::{Ctx, SceneError};

/// The time step of the scene, with the contact time and stability limit it was checked against.
pub(super) fn choose(
    ctx: &Ctx,
    sim: &SimulationSection,
    table: &MaterialTable,
    shapes: &Shapes,
    bodies: &Bodies,
    walls: &[(Range<usize>, Wall)],
) -> Result<TimeStepInfo, SceneError> {
    let speed = sim
        .characteristic_speed
        .as_ref()
        .map(|v| ctx.positive(v, "simulation.characteristic_speed"))
        .transpose()?;
    let facts = bodies.list.iter().map(|b| {
        let shape = &shapes.list[b.shape].0;
        BodyFacts {
            material: b.material,
            dynamic: b.body.is_dynamic(),
            mass: b.body.mass,
            smallest_moment: b.body.inertia.0.min(),
            bounding_radius: bounding_radius(shape),
            shape,
        }
    });
    let (estimates, kappa) = pair_estimates(table, facts, walls.iter().map(|(_, w)| w.material));
    let sim_span = sim.end_time.span();
    let (contact_time, limit) = match contact_time_and_limit(&estimates, kappa, speed) {
        Ok(x) => x,
        Err(TimeStepIssue::NeedsSpeed) => {
            return Err(ctx.invalid(sim_span, "simulation.characteristic_speed", "a power law with exponent ≠ 1 needs the characteristic impact speed (m/s) for its contact time and stability limit"))
        }
        // Nothing can touch: only a given step makes sense.
        Err(TimeStepIssue::NoContacts) => (Real::INFINITY, Real::INFINITY),
    };
    let (dt, derived) = given_or_derived(ctx, sim, contact_time, limit)?;
    Ok(TimeStepInfo {
        dt,
        derived,
        contact_time,
        stability_limit: limit,
    })
}

/// `time_step` (checked against `limit`) or `steps_per_contact` (Δt = t_c/N, checked as well): exactly one.
fn given_or_derived(
    ctx: &Ctx,
    sim: &SimulationSection,
    contact_time: Real,
    limit: Real,
) -> Result<(Real, bool), SceneError> {
    match (&sim.time_step, &sim.steps_per_contact) {
        (Some(_), Some(n)) => Err(ctx.invalid(
            n.span(),
            "simulation.steps_per_contact",
            "give either time_step or steps_per_contact, not both",
        )),
        (None, None) => Err(ctx.invalid(
            sim.end_time.span(),
            "simulation.time_step",
            "give time_step (s) or steps_per_contact (N in Δt = t_c/N)",
        )),
        (Some(dt), None) => {
            let value = ctx.positive(dt, "simulation.time_step")?;
            if value > limit {
                return Err(ctx.invalid(dt.span(), "simulation.time_step", format!(
                    "{value:e} s exceeds the stability limit {limit:e} s (2/ω_max of the stiffest contact; shortest contact time t_c = {contact_time:e} s)"
                )));
            }
            Ok((value, false))
        }
        (None, Some(n)) => {
            let n_value = ctx.positive(n, "simulation.steps_per_contact")?;
            if !contact_time.is_finite() {
                return Err(ctx.invalid(n.span(), "simulation.steps_per_contact", "no two bodies of this scene can touch, so there is no contact time: give time_step"));
            }
            let value = contact_time / n_value;
            // A contact time that under- or overflowed (densities or stiffnesses near the ends of the f64
            // range) gives a step of 0 s or a non-finite one: refuse it here rather than at the first step.
            if !(value.is_finite() && value > 0.0) {
                return Err(ctx.invalid(n.span(), "simulation.steps_per_contact", format!(
                    "the derived step t_c/N = {value:e} s is not a positive finite time (shortest contact time t_c = {contact_time:e} s): check the densities and stiffnesses for values near the limits of f64"
                )));
            }
            if value > limit {
                return Err(ctx.invalid(n.span(), "simulation.steps_per_contact", format!(
                    "t_c/N = {value:e} s exceeds the stability limit {limit:e} s; N must be at least {:.1}", contact_time / limit
                )));
            }
            Ok((value, true))
        }
    }
}
