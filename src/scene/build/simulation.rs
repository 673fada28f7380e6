//! The `[simulation]` table apart from the time step ([`super::step_size`]): gravity and the run's length,
//! the global viscous damping, the Verlet skin, and the tolerances of the step.

use crate::contact::pair_smoothing::PairSmoothing;
use crate::contact::wall_depth::{WallDepth, MAX_BAND};
use crate::dynamics::ViscousDamping;
use crate::math::{Real, Vector};
use crate::world::{StepParams, TimeStepCheck};

use toml::Spanned;

use super::super::run_length::{self, StepCountError, DEFAULT_MAX_STEPS};
use super::super::schema::SimulationSection;
use super::super::time_step::TimeStepInfo;
use super::shapes::Shapes;
use super::{Ctx, SceneError};

/// `simulation.gravity`, `end_time` and `output_interval`.
pub(super) struct RunLength {
    pub gravity: Vector,
    pub end_time: Real,
    pub output_interval: Real,
}

impl RunLength {
    pub fn read(ctx: &Ctx, sim: &SimulationSection) -> Result<Self, SceneError> {
        Ok(Self {
            gravity: ctx.vector(&sim.gravity, "simulation.gravity")?,
            end_time: ctx.positive(&sim.end_time, "simulation.end_time")?,
            output_interval: ctx.positive(&sim.output_interval, "simulation.output_interval")?,
        })
    }
}

/// The run's number of steps, end_time / Δt, refused above `simulation.max_steps` (absent =
/// [`DEFAULT_MAX_STEPS`]) or beyond the step counter, with the count, where Δt came from, the limit and how
/// to raise it.
pub(super) fn step_count(
    ctx: &Ctx,
    sim: &SimulationSection,
    run: &RunLength,
    time_step: &TimeStepInfo,
) -> Result<u64, SceneError> {
    let limit = match &sim.max_steps {
        Some(m) if *m.get_ref() == 0 => {
            return Err(ctx.invalid(m.span(), "simulation.max_steps", "must be at least 1"))
        }
        Some(m) => *m.get_ref(),
        None => DEFAULT_MAX_STEPS,
    };
    let dt = time_step.dt;
    let origin = if time_step.derived {
        format!(
            "derived: t_c / steps_per_contact, t_c = {:?} s the shortest contact time of the laws and the lightest bodies",
            time_step.contact_time
        )
    } else {
        "given by simulation.time_step".to_owned()
    };
    run_length::step_count(run.end_time, dt, limit).map_err(|e| {
        let message = match e {
            StepCountError::Overflow { steps, .. } => format!(
                "{:?} s at Δt = {dt:?} s ({origin}) is {steps:e} steps, beyond the step counter's range ({} steps): shorten end_time or lengthen the step",
                run.end_time,
                u64::MAX
            ),
            StepCountError::AboveLimit { steps, limit, .. } => format!(
                "{:?} s at Δt = {dt:?} s ({origin}) is {steps} steps, above the limit of {limit} steps: set simulation.max_steps to at least {steps} to run it",
                run.end_time
            ),
        };
        ctx.invalid(sim.end_time.span(), "simulation.end_time", message)
    })
}

/// `simulation.viscous_damping_rate`: absent = none.
pub(super) fn viscous_damping(
    ctx: &Ctx,
    sim: &SimulationSection,
) -> Result<ViscousDamping, SceneError> {
    let Some(rate) = &sim.viscous_damping_rate else {
        return Ok(ViscousDamping::None);
    };
    let r = *rate.get_ref();
    if !(r.is_finite() && r >= 0.0) {
        return Err(ctx.invalid(
            rate.span(),
            "simulation.viscous_damping_rate",
            format!("must be finite and ≥ 0, got {r}"),
        ));
    }
    Ok(ViscousDamping::MassProportional(r))
}

/// `simulation.skin`: absent = 0.2 × the smallest bounding radius of the scene's shapes (0 without one).
pub(super) fn skin(
    ctx: &Ctx,
    sim: &SimulationSection,
    shapes: &Shapes,
) -> Result<Real, SceneError> {
    let min_radius = shapes
        .list
        .iter()
        .filter_map(|(s, _)| s.length_scale())
        .fold(Real::INFINITY, Real::min)
        * 0.5;
    Ok(match &sim.skin {
        Some(s) => ctx.positive(s, "simulation.skin")?,
        None if min_radius.is_finite() => 0.2 * min_radius,
        None => 0.0,
    })
}

/// The step parameters: the time step `dt`, the global damping, and the tolerances the table sets.
pub(super) fn step_params(
    ctx: &Ctx,
    sim: &SimulationSection,
    dt: Real,
    damping: ViscousDamping,
) -> Result<StepParams, SceneError> {
    let mut params = StepParams::new(dt);
    params.damping = damping;
    params.tolerances.wall_depth = wall_depth(ctx, sim)?;
    params.tolerances.pair_smoothing = pair_smoothing(ctx, sim)?;
    params.energy_ledger = sim.energy_ledger.as_ref().is_none_or(|l| *l.get_ref());
    params.time_step_check = time_step_check(ctx, sim)?;
    Ok(params)
}

/// `simulation.time_step_check`: what the run does when its check finds the motion too fast for the
/// step (see `crate::world::step::guard`); absent = stop.
fn time_step_check(ctx: &Ctx, sim: &SimulationSection) -> Result<TimeStepCheck, SceneError> {
    let Some(value) = &sim.time_step_check else {
        return Ok(TimeStepCheck::default());
    };
    match value.get_ref().as_str() {
        "stop" => Ok(TimeStepCheck::Stop),
        "warn" => Ok(TimeStepCheck::Warn),
        "off" => Ok(TimeStepCheck::Off),
        other => Err(ctx.invalid(
            value.span(),
            "simulation.time_step_check",
            format!("must be \"stop\", \"warn\" or \"off\", got \"{other}\""),
        )),
    }
}

/// `simulation.wall_depth` and `simulation.wall_depth_band`: how a polyhedron–wall contact turns the vertex
/// depths into the law's overlap. A band given with the deepest-vertex rule is refused (it would be ignored).
fn wall_depth(ctx: &Ctx, sim: &SimulationSection) -> Result<WallDepth, SceneError> {
    let band = match &sim.wall_depth_band {
        Some(b) => Some((
            smoothing_band(ctx, b, "simulation.wall_depth_band")?,
            b.span(),
        )),
        None => None,
    };
    let rule = sim
        .wall_depth
        .as_ref()
        .map(|r| (r.get_ref().as_str(), r.span()));
    match (rule, band) {
        (None | Some(("smoothed", _)), None) => Ok(WallDepth::default()),
        (None | Some(("smoothed", _)), Some((band, _))) => Ok(WallDepth::Smoothed { band }),
        (Some(("deepest_vertex", _)), None) => Ok(WallDepth::DeepestVertex),
        (Some(("deepest_vertex", _)), Some((_, span))) => Err(ctx.invalid(
            span,
            "simulation.wall_depth_band",
            "a band applies to wall_depth = \"smoothed\" only, not to \"deepest_vertex\"",
        )),
        (Some((other, span)), _) => Err(ctx.invalid(
            span,
            "simulation.wall_depth",
            format!("must be \"smoothed\" or \"deepest_vertex\", got \"{other}\""),
        )),
    }
}

/// A smoothing band (fraction of the particle size): positive and at most [`MAX_BAND`], where the
/// smoothing's derivation holds (see [`MAX_BAND`]).
fn smoothing_band(ctx: &Ctx, band: &Spanned<f64>, field: &str) -> Result<Real, SceneError> {
    let value = ctx.positive(band, field)?;
    if value > MAX_BAND {
        return Err(ctx.invalid(band.span(), field, format!(
            "{value} exceeds {MAX_BAND}: the band should be about the scene's overlap (static overlap under load, or the peak overlap of the impacts), and overlaps beyond {MAX_BAND} of the particle size are already deep overlaps; a wider band lets the smoothed depth fall short of the true one by up to 0.22 × band × the particle size, so bodies sink into walls or each other unreported"
        )));
    }
    Ok(value)
}

/// `simulation.pair_smoothing` and `simulation.pair_smoothing_band`: the overlap a polyhedron–polyhedron
/// contact hands to the law. A band given with the exact overlap is refused (it would be ignored).
fn pair_smoothing(ctx: &Ctx, sim: &SimulationSection) -> Result<PairSmoothing, SceneError> {
    let band = match &sim.pair_smoothing_band {
        Some(b) => Some((
            smoothing_band(ctx, b, "simulation.pair_smoothing_band")?,
            b.span(),
        )),
        None => None,
    };
    let rule = sim
        .pair_smoothing
        .as_ref()
        .map(|r| (r.get_ref().as_str(), r.span()));
    match (rule, band) {
        (None | Some(("smoothed", _)), None) => Ok(PairSmoothing::default()),
        (None | Some(("smoothed", _)), Some((band, _))) => Ok(PairSmoothing::Smoothed { band }),
        (Some(("exact", _)), None) => Ok(PairSmoothing::Exact),
        (Some(("exact", _)), Some((_, span))) => Err(ctx.invalid(
            span,
            "simulation.pair_smoothing_band",
            "a band applies to pair_smoothing = \"smoothed\" only, not to \"exact\"",
        )),
        (Some((other, span)), _) => Err(ctx.invalid(
            span,
            "simulation.pair_smoothing",
            format!("must be \"smoothed\" or \"exact\", got \"{other}\""),
        )),
    }
}
