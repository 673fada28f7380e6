//! Non-structure-preserving rotation updates, kept to show what the splitting buys (see the parent module).
//!
//! Both integrate the torque-free system q̇ = ½ q ⊗ (0, ω̄), L̄̇ = L̄ × ω̄, ω̄ = J̄⁻¹ L̄, and renormalise q.

use crate::dynamics::body::PrincipalInertia;
use crate::math::{Real, Rotation, Vector};
use nalgebra::Quaternion;

/// Time derivatives (q̇, L̄̇) of the torque-free rigid body at (q, L̄).
fn derivatives(
    q: &Quaternion<Real>,
    angular_momentum_body: &Vector,
    inertia: &PrincipalInertia,
) -> (Quaternion<Real>, Vector) {
    let omega_body = inertia.angular_velocity_body(angular_momentum_body);
    let q_dot = q * Quaternion::from_parts(0.0, omega_body) * 0.5;
    (q_dot, angular_momentum_body.cross(&omega_body))
}

/// Explicit (forward) Euler, first order: q ← normalise(q + Δt q̇(q, L̄)), L̄ ← L̄ + Δt L̄̇(L̄).
pub fn drift_explicit_euler(
    orientation: &mut Rotation,
    angular_momentum_body: &mut Vector,
    inertia: &PrincipalInertia,
    dt: Real,
) {
    let q = *orientation.quaternion();
    let (q_dot, l_dot) = derivatives(&q, angular_momentum_body, inertia);
    *orientation = Rotation::from_quaternion(q + q_dot * dt);
    *angular_momentum_body += dt * l_dot;
}

/// Classical fourth-order Runge–Kutta on (q, L̄), then q renormalised.
pub fn drift_runge_kutta4(
    orientation: &mut Rotation,
    angular_momentum_body: &mut Vector,
    inertia: &PrincipalInertia,
    dt: Real,
) {
    let q0 = *orientation.quaternion();
    let l0 = *angular_momentum_body;
    let (kq1, kl1) = derivatives(&q0, &l0, inertia);
    let (kq2, kl2) = derivatives(&(q0 + kq1 * (0.5 * dt)), &(l0 + 0.5 * dt * kl1), inertia);
    let (kq3, kl3) = derivatives(&(q0 + kq2 * (0.5 * dt)), &(l0 + 0.5 * dt * kl2), inertia);
    let (kq4, kl4) = derivatives(&(q0 + kq3 * dt), &(l0 + dt * kl3), inertia);
    let q = q0 + (kq1 + kq2 * 2.0 + kq3 * 2.0 + kq4) * (dt / 6.0);
    *orientation = Rotation::from_quaternion(q);
    *angular_momentum_body = l0 + (dt / 6.0) * (kl1 + 2.0 * kl2 + 2.0 * kl3 + kl4);
}
