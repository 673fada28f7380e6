//! `simulation.time_step` or `simulation.steps_per_contact`: the step given and checked against the
//! stability limit, or derived from the shortest contact time ([`crate::scene::time_step`] has the
//! physics), from the lightest dynamic body of each material and the laws of the pairs that can meet.

use std::ops::Range;

use crate::law::pair::contact_radius;
use crate::math::Real;
use crate::world::{MaterialTable, Wall};

use super::super::schema::SimulationSection;
use super::super::time_step::{contact_time_and_limit, PairEstimate, TimeStepInfo, TimeStepIssue};
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
    let lightest = Lightest::of(table.len(), shapes, bodies, walls);
    let estimates = pair_estimates(table, &lightest);
    let sim_span = sim.end_time.span();
    let (contact_time, limit) = match contact_time_and_limit(&estimates, lightest.kappa, speed) {
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

/// Per material: the lightest dynamic body's mass and contact radius, and whether a wall or a non-dynamic
/// body of it exists; the rotational factor κ over all dynamic bodies.
struct Lightest {
    mass: Vec<Real>,
    /// Contact radius of the lightest body of each material (for laws that scale with R*).
    radius: Vec<Real>,
    has_obstacle: Vec<bool>,
    /// κ = max (1 + m r_b²/J_min) of the module docs of [`crate::scene::time_step`].
    kappa: Real,
}

impl Lightest {
    fn of(n_mat: usize, shapes: &Shapes, bodies: &Bodies, walls: &[(Range<usize>, Wall)]) -> Self {
        let mut l = Lightest {
            mass: vec![Real::INFINITY; n_mat],
            radius: vec![Real::INFINITY; n_mat],
            has_obstacle: vec![false; n_mat],
            kappa: 1.0,
        };
        for b in &bodies.list {
            let (body, mat) = (&b.body, b.material as usize);
            if body.is_dynamic() {
                let shape = &shapes.list[b.shape].0;
                if body.mass < l.mass[mat] {
                    l.mass[mat] = body.mass;
                    l.radius[mat] = contact_radius(shape).unwrap_or(Real::INFINITY);
                }
                let r = bounding_radius(shape);
                let j_min = body.inertia.0.min();
                l.kappa = l.kappa.max(1.0 + body.mass * r * r / j_min);
            } else {
                l.has_obstacle[mat] = true;
            }
        }
        for (_, w) in walls {
            l.has_obstacle[w.material as usize] = true;
        }
        l
    }
}

/// The law and effective mass of every way two materials' bodies can meet.
fn pair_estimates(table: &MaterialTable, l: &Lightest) -> Vec<PairEstimate> {
    let n_mat = table.len();
    let mut estimates = Vec::new();
    for a in 0..n_mat {
        for b in a..n_mat {
            let Some(model) = table.model(a as u32, b as u32) else {
                continue;
            };
            let (ma, mb) = (l.mass[a], l.mass[b]);
            let (ra, rb) = (l.radius[a], l.radius[b]);
            // (m*, R*) of each way the pair can meet; a wall or fixed body counts as flat (R* = R, the
            // stiffest Hertz contact of that body).
            let mut candidates = Vec::new();
            if ma.is_finite() && mb.is_finite() {
                candidates.push((ma * mb / (ma + mb), ra * rb / (ra + rb)));
            }
            if ma.is_finite() && l.has_obstacle[b] {
                candidates.push((ma, ra));
            }
            if mb.is_finite() && l.has_obstacle[a] {
                candidates.push((mb, rb));
            }
            for (m, r) in candidates {
                estimates.push(PairEstimate {
                    model: model.for_root_radius(r.sqrt()),
                    effective_mass: m,
                });
            }
        }
    }
    estimates
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
