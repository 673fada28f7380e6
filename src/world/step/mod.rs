//! One time step of the world, with its stages written out in order.
//!
//! ```text
//!  step n → n+1 (Δt):
//!   0. (first step only) evaluate the loads at the initial state       — the same stages 3–6 as below
//!   1. first half kick   v, L ← v, L + ½Δt (F_n, p_n)   with the loads kept from the previous evaluation
//!   2. drift             x, q ← x_{n+1}, q_{n+1}; walls move with their prescribed velocity
//!   3. broad phase       bounding spheres + Verlet skin → sorted body pairs; body–wall pairs by distance
//!   4. narrow phase      contact store synced to the candidate list; one contact query per candidate
//!   5. laws              ContactModel::evaluate per overlapping candidate (tangential history in the store);
//!                        4 and 5 run fused, one pass over the candidates (the store entry is in cache)
//!   6. accumulate        per-body sums of forces and torques in candidate order (fixed, deterministic:
//!                        a scatter on one thread, a gather per body over its pairs on several)
//!  6b. (sleeping on) wake the sleeping bodies whose load departs from their rest load, or that touch a
//!      moving wall or a prescribed body
//!   7. second half kick  v, L ← v, L + ½Δt (F_{n+1}, p_{n+1}); on several threads without sleeping or
//!                        prescribed bodies, each body's sums of stage 6 are taken in this pass, just before
//!                        its kick (one parallel region fewer; the same additions)
//!   8. checks            non-finite state → StepError naming body and step; deep overlaps → StepReport
//!                        (7 and the body checks of 8 run fused, one pass over the bodies)
//!  8b. (sleeping on) calm counters, bodies falling asleep (see [`super::sleeping`])
//!   9. ledger, counters
//! ```
//! Forces are evaluated once per step, at the new positions x_{n+1} (stages 3–6); the same loads close this
//! step (7) and open the next (1). The velocity-dependent parts (damping, tangential increment) see the
//! half-step velocities, as [`crate::dynamics::integrator`] documents.
//!
//! The candidate order is a function of the state only (the broad phase's sorted pairs, then body–wall
//! pairs by body and wall). Stages 4 and 5 (one query and one law evaluation per candidate), the force sums
//! of stage 6 (one body at a time, over its pairs in candidate order) and the integration (1–2, 7–8; one
//! body at a time) run on rayon's current thread pool when the scene is large enough ([`super::Parallelism`]);
//! each computes a result per item into that item's own slot, and the sums over all candidates (energy
//! terms, report) are taken serially in candidate order, so a run is bit-identical for any number of
//! threads (see [`super::parallel`]; `tests/world_parallel.rs`).
//!
//! One file per stage: `integrate` (1–2, 7–8), `broad` (3), `narrow` (4), `laws` (5), `accumulate` (6),
//! `checks` (8), `ledger` (9); `loads` runs 3–6 in order. A world of free spheres takes `sphere` for 1–2
//! and 7–8 and `sphere_kernel` inside 4–5: the same stages, the same bits. The parameters, report, error,
//! counters and scratch buffers are leaf files the stages share (`params`, `report`, `counters`,
//! `scratch`, and the time-step check's choices and findings, `findings`), and each stage is timed by a
//! [`super::timing::StageClock`].

mod accumulate;
mod broad;
mod checks;
mod consensus;
mod counters;
mod findings;
pub(crate) mod guard;
mod integrate;
mod laws;
mod ledger;
mod loads;
mod narrow;
mod params;
mod report;
mod scratch;
pub(super) mod sphere;
mod sphere_kernel;

pub use consensus::{RebuildConsensus, RebuildVote};
pub use counters::StepCounters;
pub use findings::{TimeStepCheck, TimeStepFinding};
pub use params::{StepParams, DEFAULT_OVERLAP_WARNING_FRACTION};
pub use report::{OverlapWarning, StepError, StepReport};
pub use scratch::StepScratch;

pub(crate) use checks::first_non_finite;
pub(crate) use laws::effective_models;
pub(in crate::world) use sphere_kernel::{sphere_pair_geometry, wall_sphere_geometry};

use super::sleeping;
use super::world::World;
use ledger::StepPowers;

/// Advances the world by one step `params.dt` (see the module docs for the stages), then checks the step
/// against the motion it produced (`guard`: reads the state only).
pub fn step(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
) -> Result<StepReport, StepError> {
    let mut report = advance(params, world, scratch)?;
    if params.time_step_check != TimeStepCheck::Off {
        scratch.guard.ensure(world, params.dt);
        let bodies = guard::Bodies {
            len: world.bodies.len(),
            state: |i: usize| {
                let b = &world.bodies[i];
                (b.position, b.velocity, world.radii[i])
            },
            names: &world.names,
            walls: &world.walls,
            margin: 0.5 * world.broad_phase.skin(),
        };
        guard::check(
            params.time_step_check,
            &scratch.guard,
            params.dt,
            world.step_index,
            &bodies,
            || scratch.candidates.iter().copied(),
            &mut report.counters,
            &mut report.time_step_findings,
        )?;
    }
    Ok(report)
}

/// Stage 0 alone: the loads of the initial state when they are not current (a fresh world), which the
/// next step would otherwise evaluate first. A world split over processes evaluates them apart, so that
/// each part can take its ghosts' loads from their owners before its first step reads them.
pub fn evaluate_initial_loads(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
) -> Result<StepReport, StepError> {
    let mut report = StepReport::default();
    world.sleep.resize(world.bodies.len());
    initial_loads(params, world, scratch, &mut report)?;
    Ok(report)
}

/// 0. The loads of the initial state (no tangential increment: no time has passed).
fn initial_loads(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    report: &mut StepReport,
) -> Result<(), StepError> {
    if !world.loads.current {
        loads::evaluate(params, world, scratch, report, 0.0, false)?;
        if world.ledger.initial_total.is_none() {
            world.ledger.initial_total = Some(world.energy().mechanical());
        }
    }
    Ok(())
}

/// Stages 0–9 of one step (the module docs).
fn advance(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
) -> Result<StepReport, StepError> {
    let dt = params.dt;
    if !(dt.is_finite() && dt > 0.0) {
        return Err(StepError::InvalidTimeStep {
            step: world.step_index,
            dt,
        });
    }
    let mut report = StepReport::default();
    world.sleep.resize(world.bodies.len());
    if !params.sleeping.enabled && world.sleep.sleeping > 0 {
        // Sleeping switched off: every body wakes.
        report.counters.woken += world.sleep.wake_all() as u64;
    }
    initial_loads(params, world, scratch, &mut report)?;
    if sphere::applies(params, world) {
        return sphere::step_spheres(params, world, scratch, report);
    }
    let powers = StepPowers::at_start(params.damping, world);
    let integrator = integrate::integrator(params, world);

    // 1–2. First half kick with the kept loads, drift.
    integrate::kick_and_drift(params, &integrator, world, scratch, &mut report.counters);

    // 3–6. Loads at the new positions (without sleeping, the per-body sums of a parallel evaluation are
    // left to the pass of 7–8: one parallel region fewer).
    let defer_gather = !params.sleeping.enabled;
    loads::evaluate(params, world, scratch, &mut report, dt, defer_gather)?;

    // 6b. Sleeping bodies disturbed by this evaluation wake before the second half kick.
    if params.sleeping.enabled {
        report.counters.woken += sleeping::wake_disturbed(world);
    }

    // 7–8. Second half kick, then the checks of the same body, in one pass (the first non-finite body in
    // body order is reported, for any number of threads).
    integrate::kick_and_check(params, &integrator, world, scratch, &mut report.counters)?;

    // 8b. Sleeping: calm counters, falling asleep (serial, in body order).
    if params.sleeping.enabled {
        let counts = sleeping::update(&params.sleeping, world);
        report.counters.fell_asleep += counts.fell_asleep;
        report.counters.woken += counts.woken;
    }
    report.counters.sleeping_body_steps += world.sleep.sleeping as u64;

    // 9. Ledger and counters.
    powers.close_step(params.damping, dt, world);
    report.counters.steps = 1;
    Ok(report)
}
