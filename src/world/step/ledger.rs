//! Stage 9's ledger: the powers integrated over a step by the trapezoid rule (moving walls and prescribed
//! bodies; the global viscous damping) and the contact terms booked at the end of the step.

use crate::dynamics::{Motion, RigidBody, ViscousDamping};
use crate::math::Real;

use super::super::world::{viscous_power, Loads, Wall, World};

/// Power (W) delivered to the system through contacts by the prescribed bodies among `bodies` (those
/// `counts_body` counts) and by `walls`, with the contact loads `loads` and the velocities they have now:
/// P = −Σ F·v (− Σ M·ω). `bodies` may be empty when none is prescribed (the sum skips them anyway).
pub(super) fn external_power(
    loads: &Loads,
    bodies: &[RigidBody],
    walls: &[Wall],
    counts_body: impl Fn(usize) -> bool,
) -> Real {
    let mut power = 0.0;
    for (i, body) in bodies.iter().enumerate() {
        if matches!(body.motion, Motion::Prescribed { .. }) && counts_body(i) {
            power -= loads.forces[i].dot(&body.velocity)
                + loads.torques[i].dot(&body.angular_velocity());
        }
    }
    for (w, wall) in walls.iter().enumerate() {
        power -= loads.wall_forces[w].dot(&wall.velocity);
    }
    power
}

/// The powers stage 9 integrates over a step by the trapezoid rule, as they were at its start: the
/// external power of the moving walls and the global viscous damping's power. Both step paths (the
/// general one and [`super::sphere`]) take them at the start and close the step with them.
pub(super) struct StepPowers {
    external: Real,
    viscous: Real,
}

/// The global viscous damping's power at the current state; zero without damping (no pass over the
/// bodies).
fn damping_power(damping: ViscousDamping, world: &World) -> Real {
    if damping != ViscousDamping::None {
        viscous_power(world, |m| damping.coefficient(m))
    } else {
        0.0
    }
}

impl StepPowers {
    /// The powers at the start of a step. The external power is taken with the velocities the walls and
    /// prescribed bodies have now, i.e. those this step moves them with: a caller that changed a velocity
    /// since the last evaluation (a servo-controlled wall) would otherwise book the work of the old one.
    /// With unchanged velocities it is the evaluation's `external_power`, bit for bit.
    /// It costs one pass over the bodies' motion tags per step (the prescribed ones may have been changed
    /// too, and a step after a checkpoint load has no record of which bodies are prescribed).
    pub(super) fn at_start(damping: ViscousDamping, world: &World) -> Self {
        Self {
            external: external_power(&world.loads, &world.bodies, &world.walls, |i| {
                world.counts_body(i)
            }),
            viscous: damping_power(damping, world),
        }
    }

    /// Stage 9: books the step's contact dissipation and work, the trapezoids of the two powers over `dt`,
    /// and advances the time and the step index.
    pub(super) fn close_step(self, damping: ViscousDamping, dt: Real, world: &mut World) {
        let viscous_end = damping_power(damping, world);
        let ledger = &mut world.ledger;
        ledger.dissipated_damping += world.loads.damping_work;
        ledger.dissipated_friction += world.loads.friction_dissipation;
        ledger.tangential_stiffness_work += world.loads.tangential_stiffness_work;
        ledger.dissipated_viscous += 0.5 * (self.viscous + viscous_end) * dt;
        ledger.external_work += 0.5 * (self.external + world.loads.external_power) * dt;
        world.time += dt;
        world.step_index += 1;
    }
}
