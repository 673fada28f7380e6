//! One body's time step, kick–drift–kick, for every kind of [`Motion`].
//!
//! A world step calls, for each body: [`Integrator::first_half_kick`] with the forces and torques of t_n,
//! [`Integrator::drift`], then (after the contact stages at t_{n+1}) [`Integrator::second_half_kick`]. For a
//! dynamic body this is velocity Verlet in translation and the leapfrog-equivalent arrangement of the
//! paper's rotation scheme (see [`crate::dynamics::rotation`] for why the half kicks reproduce eq. 18).
//! Fixed bodies keep zero velocities; prescribed bodies move kinematically and ignore forces.
//!
//! Velocity-dependent forces (contact damping, friction increments) evaluated between the drift and the
//! second half kick see the half-step velocities v_{n+1/2}, ω_{n+1/2}: the scheme is then first order in
//! those terms. Measured effect (tests/law_gates.rs): the restitution of a damped collision is within
//! 2 Δt/t_c of its input, e.g. 0.17 % for the Hertz law at Δt = t_c/200.

use crate::dynamics::body::{Motion, RigidBody};
use crate::dynamics::rotation::{drift_rotation, RotationScheme};
use crate::dynamics::translation::{
    drift_position, first_half_kick, second_half_kick, TranslationParams,
};
use crate::math::{Real, Rotation, Vector};

/// The integrator's choices, shared by all bodies.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Integrator {
    /// How positions and velocities are advanced (leapfrog and its options).
    pub translation: TranslationParams,
    /// How orientations and angular velocities are advanced.
    pub rotation: RotationScheme,
}

impl Integrator {
    /// Half kick at the start of a step of length `dt`, with the resultant force (N) and torque about the
    /// centre of mass (N·m, world) at t_n: v ← v + ½Δt a_n, L ← L + ½Δt p_n.
    pub fn first_half_kick(&self, body: &mut RigidBody, force: &Vector, torque: &Vector, dt: Real) {
        if self.apply_kinematics(body) {
            return;
        }
        first_half_kick(body, force, &self.translation, 0.5 * dt);
        kick_angular_momentum(body, torque, 0.5 * dt);
    }

    /// Drift over `dt`: x ← x + Δt v, and the torque-free rotation by the chosen scheme.
    pub fn drift(&self, body: &mut RigidBody, dt: Real) {
        match body.motion {
            Motion::Fixed => {}
            Motion::Prescribed {
                velocity,
                angular_velocity_world,
            } => {
                body.position += dt * velocity;
                body.orientation =
                    Rotation::from_scaled_axis(dt * angular_velocity_world) * body.orientation;
                body.orientation.renormalize_fast();
            }
            Motion::Dynamic => {
                drift_position(body, dt);
                let mut angular_momentum_body = body.angular_momentum_body();
                drift_rotation(
                    self.rotation,
                    &mut body.orientation,
                    &mut angular_momentum_body,
                    &body.inertia,
                    dt,
                );
                match self.rotation {
                    // The world L is an exact invariant of every sub-flow of the splitting: keep it, and let
                    // the orientation carry the motion (L̄ = Rᵀ L is re-derived when needed).
                    RotationScheme::Splitting { .. } => {}
                    // The comparison schemes integrate L̄ directly and do not keep R L̄ fixed: the world L
                    // is what they make of it.
                    RotationScheme::ExplicitEuler | RotationScheme::RungeKutta4 => {
                        body.angular_momentum =
                            body.orientation.transform_vector(&angular_momentum_body);
                    }
                }
            }
        }
    }

    /// Half kick at the end of a step, with the force and torque at t_{n+1}.
    pub fn second_half_kick(
        &self,
        body: &mut RigidBody,
        force: &Vector,
        torque: &Vector,
        dt: Real,
    ) {
        if self.apply_kinematics(body) {
            return;
        }
        second_half_kick(body, force, &self.translation, 0.5 * dt);
        kick_angular_momentum(body, torque, 0.5 * dt);
    }

    /// A whole step of a body on which only gravity acts (no contact force or torque).
    pub fn step_free(&self, body: &mut RigidBody, dt: Real) {
        let zero = Vector::zeros();
        self.first_half_kick(body, &zero, &zero, dt);
        self.drift(body, dt);
        self.second_half_kick(body, &zero, &zero, dt);
    }

    /// Sets the velocities of fixed and prescribed bodies; returns true when the body is not dynamic.
    fn apply_kinematics(&self, body: &mut RigidBody) -> bool {
        match body.motion {
            Motion::Dynamic => false,
            Motion::Fixed => {
                body.velocity = Vector::zeros();
                body.angular_momentum = Vector::zeros();
                true
            }
            Motion::Prescribed {
                velocity,
                angular_velocity_world,
            } => {
                body.velocity = velocity;
                body.set_angular_velocity(&angular_velocity_world);
                true
            }
        }
    }
}

/// L ← L + h p (world frame).
fn kick_angular_momentum(body: &mut RigidBody, torque: &Vector, h: Real) {
    body.angular_momentum += h * torque;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::body::PrincipalInertia;
    use crate::dynamics::translation::ViscousDamping;
    use crate::math::Point;

    fn integrator(gravity: Vector, damping: ViscousDamping) -> Integrator {
        Integrator {
            translation: TranslationParams { gravity, damping },
            rotation: RotationScheme::default(),
        }
    }

    fn ball(mass: Real) -> RigidBody {
        let inertia = PrincipalInertia::new(Vector::repeat(0.4 * mass * 0.01)).unwrap();
        RigidBody::new_dynamic(Point::origin(), mass, inertia).unwrap()
    }

    #[test]
    fn free_fall_is_exact() {
        // Velocity Verlet is exact for a constant force: x = v₀t + ½gt², v = v₀ + gt.
        let g = Vector::new(0.0, 0.0, -9.81);
        let it = integrator(g, ViscousDamping::None);
        let mut body = ball(2.0);
        body.velocity = Vector::new(1.0, 0.5, 3.0);
        let (dt, steps) = (1e-3, 1000);
        for _ in 0..steps {
            it.step_free(&mut body, dt);
        }
        let t = dt * steps as Real;
        let expected_x = Vector::new(1.0, 0.5, 3.0) * t + 0.5 * g * t * t;
        let expected_v = Vector::new(1.0, 0.5, 3.0) + g * t;
        let length = expected_x.norm();
        assert!(
            (body.position.coords - expected_x).norm() < 1e-12 * length,
            "position {:?}, expected {expected_x:?}, tolerance 1e-12·{length}",
            body.position
        );
        assert!(
            (body.velocity - expected_v).norm() < 1e-12 * expected_v.norm(),
            "velocity {:?}, expected {expected_v:?}",
            body.velocity
        );
    }

    #[test]
    fn damped_velocity_decays_by_the_pade_factor_and_converges_to_the_exponential() {
        let rate = 5.0;
        let v0 = Vector::new(2.0, -1.0, 0.5);
        let t_end = 0.4;
        let mut errors = Vec::new();
        for steps in [100, 200, 400] {
            let dt = t_end / steps as Real;
            let it = integrator(Vector::zeros(), ViscousDamping::MassProportional(rate));
            let mut body = ball(3.0);
            body.velocity = v0;
            for _ in 0..steps {
                it.step_free(&mut body, dt);
            }
            let factor = (1.0 - 0.5 * dt * rate) / (1.0 + 0.5 * dt * rate);
            let pade = v0 * factor.powi(steps);
            assert!(
                (body.velocity - pade).norm() < 1e-13 * v0.norm(),
                "dt = {dt}: velocity {:?}, Padé prediction {pade:?}",
                body.velocity
            );
            errors.push((body.velocity - v0 * (-rate * t_end).exp()).norm());
        }
        let order = (errors[0] / errors[2]).log2() / 2.0;
        assert!(
            (order - 2.0).abs() < 0.1,
            "damping convergence order {order}, errors {errors:?}, expected 2 ± 0.1"
        );
    }

    #[test]
    fn fixed_and_prescribed_bodies_ignore_forces() {
        let it = integrator(Vector::new(0.0, 0.0, -9.81), ViscousDamping::None);
        let mut fixed = ball(1.0);
        fixed.motion = Motion::Fixed;
        fixed.velocity = Vector::new(1.0, 0.0, 0.0);
        let force = Vector::new(5.0, 5.0, 5.0);
        it.first_half_kick(&mut fixed, &force, &force, 0.01);
        it.drift(&mut fixed, 0.01);
        it.second_half_kick(&mut fixed, &force, &force, 0.01);
        assert_eq!(fixed.position, Point::origin());
        assert_eq!(fixed.velocity, Vector::zeros());
        assert_eq!(fixed.angular_momentum, Vector::zeros());

        let mut wall = ball(1.0);
        let (v, w) = (Vector::new(0.0, 0.0, -0.1), Vector::new(0.0, 0.0, 2.0));
        wall.motion = Motion::Prescribed {
            velocity: v,
            angular_velocity_world: w,
        };
        for _ in 0..100 {
            it.first_half_kick(&mut wall, &force, &force, 0.01);
            it.drift(&mut wall, 0.01);
            it.second_half_kick(&mut wall, &force, &force, 0.01);
        }
        assert!(
            (wall.position.coords - v).norm() < 1e-14,
            "prescribed position {:?}",
            wall.position
        );
        let expected = Rotation::from_axis_angle(&Vector::z_axis(), 2.0);
        assert!(
            wall.orientation.angle_to(&expected) < 1e-12,
            "prescribed orientation {:?}, expected {expected:?}",
            wall.orientation
        );
        assert_eq!(wall.velocity, v);
        assert!(
            (wall.angular_velocity() - w).norm() < 1e-14,
            "prescribed ω {:?}",
            wall.angular_velocity()
        );
    }

    #[test]
    fn constant_torque_on_a_sphere_gives_uniform_angular_acceleration() {
        // Isotropic inertia: ω(t) = p t / J exactly, the rotation angle is ½ p t² / J.
        let it = integrator(Vector::zeros(), ViscousDamping::None);
        let mut body = ball(1.0);
        let j = body.inertia.0[0];
        let torque = Vector::new(0.0, 0.02, 0.0);
        let (dt, steps) = (1e-3, 500);
        for _ in 0..steps {
            it.first_half_kick(&mut body, &Vector::zeros(), &torque, dt);
            it.drift(&mut body, dt);
            it.second_half_kick(&mut body, &Vector::zeros(), &torque, dt);
        }
        let t = dt * steps as Real;
        let omega = torque / j * t;
        assert!(
            (body.angular_velocity() - omega).norm() < 1e-12 * omega.norm(),
            "ω = {:?}, expected {omega:?}",
            body.angular_velocity()
        );
        let expected = Rotation::from_scaled_axis(0.5 * torque / j * t * t);
        let angle = body.orientation.angle_to(&expected);
        assert!(angle < 1e-6, "orientation off by {angle} rad after {steps} steps, tolerance 1e-6 (Cayley angle error O(θ³))");
    }
}
