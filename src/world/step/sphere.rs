//! The step of a world whose bodies are all free spheres: the integration stages (1–2, 7–8) without the
//! per-body tests that only other bodies need.
//!
//! [`super::step`] hands a step to [`step_spheres`] when [`applies`] holds: the `sphere_kernel` skip
//! and the `isotropic_rotation` and `still_rotation` skips are on, the rotation scheme is the splitting,
//! sleeping is off (no body asleep), the loads are current (not the first step), and every body is a
//! dynamic sphere with equal principal moments. For such a body the general stages decide, per body and
//! per step, that it is not asleep, not a fixed body at rest, not kinematic, dynamic, and isotropic; here
//! those answers are known for the whole world from one pass over it, and each body goes straight to:
//! - 1–2: v ← v + ½Δt (F/m + g − (c/m) v), L ← L + ½Δt p, x ← x + Δt v, the orientation turned about L
//!   ([`drift_isotropic`], or not at all for L = 0: the general path's `still_rotation` branch);
//! - 7–8: the second half kick, then the finiteness check of its loads and state (the general step's
//!   `non_finite_quantity` of [`super::checks`]: one sum of the 22 values first, the quantities one by one
//!   only when it is not finite).
//!
//! Stages 3–6 are the general ones (with the sphere kernel of [`super::sphere_kernel`]), and so are the
//! ledger and counters of stage 9. Every value is computed by the same functions in the same order, so
//! the path is exact: the same bits as the general step, for any number of threads
//! (`tests/world_sphere_fast_paths.rs` compares the two, and one and two threads).

use crate::dynamics::rotation::{drift_isotropic, is_isotropic, SubRotation};
use crate::dynamics::translation::{drift_position, first_half_kick, second_half_kick};
use crate::dynamics::{Motion, RigidBody, RotationScheme, TranslationParams};
use crate::math::{Real, Vector};
use crate::shape::Shape;

use super::super::body_inputs;
use super::super::parallel::{for_each_item3, integration_work};
use super::super::region_profile::Section;
use super::super::timing::{Stage, StageClock};
use super::super::world::World;
use super::checks::non_finite_quantity;
use super::counters::StepCounters;
use super::integrate::kick_each_body;
use super::ledger::StepPowers;
use super::loads;
use super::params::StepParams;
use super::report::{StepError, StepReport};
use super::scratch::StepScratch;

/// Whether the next step of `world` under `params` takes the free-sphere path of `step_spheres` (see
/// the module docs; exported as `world::sphere_step_applies` for the tests that compare the two paths).
pub fn applies(params: &StepParams, world: &World) -> bool {
    let skips = &params.skips;
    let eligible = skips.sphere_kernel
        && skips.isotropic_rotation
        && skips.still_rotation
        && matches!(params.rotation, RotationScheme::Splitting { .. })
        && !params.sleeping.enabled
        && world.sleep.sleeping == 0
        && world.loads.current
        && world.loads.forces.len() == world.bodies.len();
    if !eligible {
        return false;
    }
    world.bodies.iter().zip(&world.shape_of).all(|(b, &s)| {
        matches!(b.motion, Motion::Dynamic)
            && matches!(world.shapes[s as usize], Shape::Sphere(_))
            && is_isotropic(&b.inertia.0)
    })
}

/// Stages 1–2 for one free sphere (the general stage's branch for a dynamic isotropic body).
#[inline(always)]
fn kick_and_drift(
    body: &mut RigidBody,
    force: &Vector,
    torque: &Vector,
    translation: &TranslationParams,
    form: SubRotation,
    dt: Real,
) {
    let h = 0.5 * dt;
    first_half_kick(body, force, translation, h);
    body.angular_momentum += h * torque;
    drift_position(body, dt);
    if body.angular_momentum == Vector::zeros() {
        return;
    }
    let moment = body.inertia.0.x;
    drift_isotropic(
        form,
        &mut body.orientation,
        &body.angular_momentum,
        moment,
        dt,
    );
}

/// Stages 7–8 for one free sphere: the second half kick, then the first non-finite quantity, if any.
#[inline(always)]
fn kick_and_check(
    body: &mut RigidBody,
    force: &Vector,
    torque: &Vector,
    translation: &TranslationParams,
    dt: Real,
) -> Option<&'static str> {
    let h = 0.5 * dt;
    second_half_kick(body, force, translation, h);
    body.angular_momentum += h * torque;
    non_finite_quantity(body, force, torque)
}

/// One step of a world of free spheres (call only when [`applies`] holds; the step's input checks and the
/// initial evaluation of the loads are done by the caller). `report` is the caller's report so far.
pub(super) fn step_spheres(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    mut report: StepReport,
) -> Result<StepReport, StepError> {
    let dt = params.dt;
    let translation = TranslationParams {
        gravity: world.gravity,
        damping: params.damping,
    };
    let RotationScheme::Splitting { sub_rotation: form } = params.rotation else {
        unreachable!("applies() admits the splitting scheme only")
    };
    let powers = StepPowers::at_start(params.damping, world);

    // 1–2. First half kick with the kept loads, drift.
    drift_all(
        params,
        &translation,
        form,
        world,
        scratch,
        &mut report.counters,
    );

    // 3–6. Loads at the new positions (sleeping is off: the sums of a parallel evaluation may wait).
    loads::evaluate(params, world, scratch, &mut report, dt, true)?;

    // 7–8. Second half kick and checks, in one pass.
    kick_all(params, &translation, world, scratch, &mut report.counters)?;

    // 9. Ledger and counters (as the general step).
    powers.close_step(params.damping, dt, world);
    report.counters.steps = 1;
    Ok(report)
}

/// Stages 1–2 of every sphere, with the per-body inputs of stage 3 written in the same pass (as the
/// general stage does), and the walls moved.
fn drift_all(
    params: &StepParams,
    translation: &TranslationParams,
    form: SubRotation,
    world: &mut World,
    scratch: &mut StepScratch,
    counters: &mut StepCounters,
) {
    let dt = params.dt;
    let mut clock = StageClock::start();
    let parallel_bodies = integration_work(world.bodies.len(), scratch.inputs.summary.anisotropic)
        >= params.parallel.min_bodies;
    let loads = &world.loads;
    // The drift pass also writes what stage 3 reads of each body, as the general one does.
    let inputs = &mut scratch.inputs;
    inputs.resize(world.bodies.len());
    let (at_build, limit_sq) = (
        world.broad_phase.centres_at_build(),
        world.broad_phase.rebuild_limit_sq(),
    );
    clock.region(Section::KickDrift, parallel_bodies, || {
        for_each_item3(
            parallel_bodies,
            &mut world.bodies,
            &mut inputs.centres,
            &mut inputs.flags,
            |i, body, centre, flags| {
                kick_and_drift(
                    body,
                    &loads.forces[i],
                    &loads.torques[i],
                    translation,
                    form,
                    dt,
                );
                *centre = body.position;
                *flags = body_inputs::flags_of(i, body, at_build, limit_sq);
            },
        )
    });
    inputs.fresh = true;
    for wall in &mut world.walls {
        wall.pose.translation.vector += dt * wall.velocity;
    }
    counters.add(Stage::Integrate, clock.stop());
}

/// Stages 7–8 of every sphere in one pass (with stage 6's per-body sums first when it left them here);
/// the first non-finite body in body order is the error.
fn kick_all(
    params: &StepParams,
    translation: &TranslationParams,
    world: &mut World,
    scratch: &mut StepScratch,
    counters: &mut StepCounters,
) -> Result<(), StepError> {
    let dt = params.dt;
    kick_each_body(
        params,
        world,
        scratch,
        counters,
        |_, _, body, force, torque| kick_and_check(body, force, torque, translation, dt),
    )
}
