//! Stages 3–6 in order: the loads at the current positions.

use crate::math::Real;

use super::super::world::World;
use super::params::StepParams;
use super::report::{StepError, StepReport};
use super::scratch::StepScratch;
use super::{accumulate, broad, narrow};

/// Stages 3–6 at the current positions; `dt` is the tangential increment's time (0 at the initial state).
/// With `defer_gather`, a parallel evaluation may leave the per-body sums of stage 6 to the pass of 7–8.
pub(super) fn evaluate(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    report: &mut StepReport,
    dt: Real,
    defer_gather: bool,
) -> Result<(), StepError> {
    // The angular velocities of this step's drift pass, if it ran (consumed first: never read stale).
    let omegas_fresh = std::mem::take(&mut scratch.inputs.omegas_fresh);
    broad::stage(params, world, scratch, &mut report.counters);
    let pass = narrow::stage(
        params,
        world,
        scratch,
        &mut report.counters,
        dt,
        omegas_fresh,
    )?;
    accumulate::stage(params, world, scratch, report, pass, defer_gather);
    Ok(())
}
