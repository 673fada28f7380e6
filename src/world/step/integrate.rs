//! Stages 1–2 (first half kick, drift) and 7–8 (second half kick with the checks of the same body) of the
//! general step: one pass over the bodies each, on the pool when the scene is large enough.

use crate::dynamics::rotation::{drift_isotropic, is_isotropic};
use crate::dynamics::translation::drift_position;
use crate::dynamics::{Integrator, Motion, RigidBody, RotationScheme, TranslationParams};
use crate::math::Vector;

use super::super::body_inputs;
use super::super::parallel::{
    for_each_item3_checked, for_each_item4, for_each_item_checked, integration_work,
};
use super::super::region_profile::Section;
use super::super::sleep_state::SleepState;
use super::super::timing::{Stage, StageClock};
use super::super::world::World;
use super::accumulate::sum_body_loads;
use super::checks::non_finite_quantity;
use super::counters::StepCounters;
use super::params::StepParams;
use super::report::StepError;
use super::scratch::StepScratch;

/// The integrator of this step: the world's gravity, the parameters' damping and rotation scheme.
pub(super) fn integrator(params: &StepParams, world: &World) -> Integrator {
    Integrator {
        translation: TranslationParams {
            gravity: world.gravity,
            damping: params.damping,
        },
        rotation: params.rotation,
    }
}

/// Stages 1–2: the first half kick with the kept loads, the drift, the walls moved; the same pass writes
/// what stage 3 reads of each body (centre, flags, ω; see [`super::super::body_inputs`]).
pub(super) fn kick_and_drift(
    params: &StepParams,
    integrator: &Integrator,
    world: &mut World,
    scratch: &mut StepScratch,
    counters: &mut StepCounters,
) {
    let dt = params.dt;
    let mut clock = StageClock::start();
    let parallel_bodies = integration_work(world.bodies.len(), scratch.inputs.summary.anisotropic)
        >= params.parallel.min_bodies;
    let (loads, asleep) = (&world.loads, &world.sleep);
    let skip = params.skips;
    let splitting = match params.rotation {
        RotationScheme::Splitting { sub_rotation } => Some(sub_rotation),
        _ => None,
    };
    let inputs = &mut scratch.inputs;
    inputs.resize(world.bodies.len());
    inputs.resize_omegas(world.bodies.len());
    let (at_build, limit_sq) = (
        world.broad_phase.centres_at_build(),
        world.broad_phase.rebuild_limit_sq(),
    );
    let kick_drift = |i: usize, body: &mut RigidBody| {
        if asleep.is_asleep(i) || (skip.non_dynamic_pairs && is_at_rest_fixed(body)) {
            return;
        }
        integrator.first_half_kick(body, &loads.forces[i], &loads.torques[i], dt);
        if let (Some(form), true) = (splitting, body.is_dynamic()) {
            if skip.still_rotation && body.angular_momentum == Vector::zeros() {
                // Zero angular momentum: the rotation sub-flows are identities (see `skips`).
                drift_position(body, dt);
                return;
            }
            if skip.isotropic_rotation && is_isotropic(&body.inertia.0) {
                // Equal principal moments: the free rotation is one turn about L (see `skips`).
                drift_position(body, dt);
                let moment = body.inertia.0.x;
                drift_isotropic(
                    form,
                    &mut body.orientation,
                    &body.angular_momentum,
                    moment,
                    dt,
                );
                return;
            }
        }
        integrator.drift(body, dt);
    };
    clock.region(Section::KickDrift, parallel_bodies, || {
        for_each_item4(
            parallel_bodies,
            &mut world.bodies,
            &mut inputs.centres,
            &mut inputs.flags,
            &mut inputs.omegas,
            |i, body, centre, flags, omega| {
                kick_drift(i, body);
                *centre = body.position;
                *flags = body_inputs::flags_of(i, body, at_build, limit_sq);
                *omega = body_inputs::omega_of(body, skip.isotropic_rotation);
            },
        )
    });
    inputs.fresh = true;
    inputs.omegas_fresh = true;
    for wall in &mut world.walls {
        wall.pose.translation.vector += dt * wall.velocity;
    }
    counters.add(Stage::Integrate, clock.stop());
}

/// Stages 7–8: the second half kick, then the checks of the same body, in one pass; the first non-finite
/// body in body order is reported, for any number of threads (see [`kick_each_body`]).
pub(super) fn kick_and_check(
    params: &StepParams,
    integrator: &Integrator,
    world: &mut World,
    scratch: &mut StepScratch,
    counters: &mut StepCounters,
) -> Result<(), StepError> {
    let (dt, skip) = (params.dt, params.skips);
    kick_each_body(
        params,
        world,
        scratch,
        counters,
        |sleep, i, body, force, torque| {
            if !(sleep.is_asleep(i) || (skip.non_dynamic_pairs && is_at_rest_fixed(body))) {
                integrator.second_half_kick(body, force, torque, dt);
            }
            non_finite_quantity(body, force, torque)
        },
    )
}

/// The pass of stages 7–8 that every layout of the general step shares: `kick` on each body with its
/// loads and the world's sleep flags, the first non-finite quantity it reports (in body order, for any
/// number of threads) the error.
/// When stage 6 left the per-body sums to this pass ([`StepScratch::deferred_gather`]), body i's sums
/// over its pairs in candidate order (the same additions as stage 6's gather) come first.
pub(super) fn kick_each_body(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    counters: &mut StepCounters,
    kick: impl Fn(&SleepState, usize, &mut RigidBody, &Vector, &Vector) -> Option<&'static str> + Sync,
) -> Result<(), StepError> {
    let mut clock = StageClock::start();
    let parallel_bodies = integration_work(world.bodies.len(), scratch.inputs.summary.anisotropic)
        >= params.parallel.min_bodies;
    let non_finite = if std::mem::take(&mut scratch.deferred_gather) {
        let n_bodies = world.bodies.len();
        let adjacency = clock.serial(Section::SerialStore, || {
            world.contacts.body_adjacency(n_bodies)
        });
        let evaluated = &scratch.evaluated;
        let (loads, sleep) = (&mut world.loads, &world.sleep);
        clock.region(Section::KickChecks, true, || {
            for_each_item3_checked(
                true,
                &mut world.bodies,
                &mut loads.forces,
                &mut loads.torques,
                |i, body, force, torque| {
                    sum_body_loads(adjacency, evaluated, i, force, torque);
                    kick(sleep, i, body, force, torque)
                },
            )
        })
    } else {
        let (loads, sleep) = (&world.loads, &world.sleep);
        clock.region(Section::KickChecks, parallel_bodies, || {
            for_each_item_checked(parallel_bodies, &mut world.bodies, |i, body| {
                kick(sleep, i, body, &loads.forces[i], &loads.torques[i])
            })
        })
    };
    counters.add(Stage::Integrate, clock.stop());
    match non_finite {
        Some(found) => Err(StepError::non_finite(world, found)),
        None => Ok(()),
    }
}

/// A fixed body whose velocities are already zero: integrating it changes nothing.
fn is_at_rest_fixed(body: &RigidBody) -> bool {
    matches!(body.motion, Motion::Fixed)
        && body.velocity == Vector::zeros()
        && body.angular_momentum == Vector::zeros()
}
