//! A sphere launched without spin along the wall z = 0 under gravity: it slides until v = ωR, then rolls.
//! The friction impulse gives v = (5/7) v₀ whatever μ (angular momentum about the contact point is
//! conserved). The sphere starts at the static overlap of the law so that the contact persists. Used by the
//! `friction` case and by `tests/sphere_gates.rs`.

use polydem::dynamics::{
    Integrator, Motion, PrincipalInertia, RigidBody, RotationScheme, TranslationParams,
    ViscousDamping,
};
use polydem::law::{ContactKinematics, ContactModel, TangentialHistory};
use polydem::math::{Point, Real, Vector};

use super::two_body::wall_sphere;

/// The state after the run.
#[derive(Clone, Debug)]
pub struct Rolling {
    /// Velocity along x (m/s).
    pub velocity: Real,
    /// ω_y R (m/s): equal to `velocity` when rolling without slip.
    pub rolling_speed: Real,
    /// Steps in which the normal force was not positive (the sphere left the wall).
    pub lost_contact: usize,
    /// The sliding time 2 v₀/(7 μ g) (s) of the rigid-body analysis.
    pub sliding_time: Real,
}

/// Runs for `sliding_times` × the sliding time, dt = 1/100 of the normal oscillation period about the static
/// overlap. `model` must be a power law (stiffness k, exponent n) with a tangential law of friction `mu`.
pub fn roll(
    model: &ContactModel,
    radius: Real,
    mass: Real,
    v0: Real,
    mu: Real,
    g: Real,
    sliding_times: Real,
) -> Rolling {
    let (k, n) = (model.normal.stiffness, model.normal.exponent);
    let static_overlap = (mass * g / k).powf(1.0 / n);
    let inertia =
        PrincipalInertia::new(Vector::repeat(0.4 * mass * radius * radius)).expect("I > 0");
    let mut wall = RigidBody::new_dynamic(Point::origin(), mass, inertia).expect("body");
    wall.motion = Motion::Fixed;
    let mut ball =
        RigidBody::new_dynamic(Point::new(0.0, 0.0, radius - static_overlap), mass, inertia)
            .expect("body");
    ball.velocity = Vector::new(v0, 0.0, 0.0);
    // Normal oscillation period about the static overlap, from the tangent stiffness n k δ^(n−1).
    let stiffness = n * k * static_overlap.powf(n - 1.0);
    let period = 2.0 * std::f64::consts::PI * (mass / stiffness).sqrt();
    let dt = period / 100.0;
    let sliding_time = 2.0 * v0 / (7.0 * mu * g);
    let steps = (sliding_times * sliding_time / dt) as usize;
    let integrator = Integrator {
        translation: TranslationParams {
            gravity: Vector::new(0.0, 0.0, -g),
            damping: ViscousDamping::None,
        },
        rotation: RotationScheme::default(),
    };
    let mut history = TangentialHistory::default();
    let evaluate = |ball: &RigidBody, history: &mut TangentialHistory| {
        let geometry = wall_sphere(radius, ball);
        let kinematics = ContactKinematics {
            relative_velocity: ball.velocity_at(&geometry.point),
            effective_mass: mass,
            center_a: wall.position,
            center_b: ball.position,
            dt,
        };
        model.evaluate(&geometry, &kinematics, history)
    };
    let mut response = evaluate(&ball, &mut history);
    let mut lost_contact = 0;
    for _ in 0..steps {
        integrator.first_half_kick(&mut ball, &response.force_on_b, &response.torque_on_b, dt);
        integrator.drift(&mut ball, dt);
        response = evaluate(&ball, &mut history);
        integrator.second_half_kick(&mut ball, &response.force_on_b, &response.torque_on_b, dt);
        if response.normal_force <= 0.0 {
            lost_contact += 1;
        }
    }
    Rolling {
        velocity: ball.velocity.x,
        rolling_speed: ball.angular_velocity().y * radius,
        lost_contact,
        sliding_time,
    }
}
