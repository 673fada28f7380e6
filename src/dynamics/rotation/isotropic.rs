//! The free rotation of a body with isotropic inertia (J̄₁ = J̄₂ = J̄₃ = J, a sphere): one turn about L.
//!
//! With J = J·I the kinetic energy T = |L|²/(2J) depends on |L| only, so ω = L/J is parallel to the world
//! angular momentum L, which is constant in a torque-free drift: the body turns uniformly about the fixed
//! axis L̂ by θ = Δt |L| / J. That single turn is the exact flow of T, so it needs no splitting. The DLM
//! composition of the parent module is *not* exact for such a body: its sub-Hamiltonians
//! T_i = L̄_i²/(2J) do not commute ({T₁, T₂} ∝ L̄₁ L̄₂ L̄₃ ≠ 0), and the composition of the five body-axis turns
//! differs from the turn about L by O(Δt³) per step — which is why this fast path is a switchable skip
//! (`world::skips`, `isotropic_rotation`) with its difference bounded in `tests/world_isotropic.rs`.
//!
//! As a rotation vector a = Δt L / J (world frame, |a| = θ), the turn is q ← q_a ⊗ q (a world-frame turn
//! multiplies on the left). [`SubRotation`] selects the quaternion q_a as in the sub-steps:
//! - `Exact`: q_a = (cos θ/2, sin(θ/2) â);
//! - `Cayley`: the paper's eq. 21 applied to the whole angle, q_a = ((1 − θ²/16), a/2) / (1 + θ²/16), the
//!   turn by 4 atan(θ/4) about â — no square root or trigonometric call, and still the exact flow of a
//!   modified T̃(|L|) (the argument of the parent module's docs, with |L| in place of L̄_i).
//!
//! L itself is not touched (the world momentum is an exact invariant of the turn), and the quaternion is
//! renormalised once, as after the splitting.

use super::SubRotation;
use crate::math::{Real, Rotation, Vector};
use nalgebra::Quaternion;

/// Whether the principal moments are exactly equal (the fast path applies; no tolerance: a body whose
/// moments differ by round-off takes the general splitting).
#[inline]
pub fn is_isotropic(moments: &Vector) -> bool {
    moments.x == moments.y && moments.y == moments.z
}

/// Turns `orientation` (body → world) over `dt` about the world angular momentum `angular_momentum` of a
/// body with isotropic principal moment `moment` (kg·m²), by the angle Δt|L|/J (`Exact`) or its Cayley
/// form 4 atan(θ/4) (`Cayley`).
#[inline(always)]
pub fn drift_isotropic(
    form: SubRotation,
    orientation: &mut Rotation,
    angular_momentum: &Vector,
    moment: Real,
    dt: Real,
) {
    let a = angular_momentum * (dt / moment);
    let theta_sq = a.norm_squared();
    if theta_sq == 0.0 {
        return;
    }
    let (w, imaginary) = match form {
        SubRotation::Cayley => {
            let quarter = theta_sq / 16.0;
            let reciprocal = 1.0 / (1.0 + quarter);
            ((1.0 - quarter) * reciprocal, a * (0.5 * reciprocal))
        }
        SubRotation::Exact => {
            let theta = theta_sq.sqrt();
            let (s, c) = (0.5 * theta).sin_cos();
            (c, a * (s / theta))
        }
    };
    let turn = Rotation::new_unchecked(Quaternion::from_parts(w, imaginary));
    *orientation = turn * *orientation;
    orientation.renormalize_fast();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::body::PrincipalInertia;
    use crate::dynamics::rotation::drift_splitting;

    #[test]
    fn exact_turn_equals_the_axis_angle_rotation_about_the_momentum() {
        let q0 = Rotation::from_scaled_axis(Vector::new(0.4, -0.2, 0.9));
        let l = Vector::new(0.3, -1.2, 0.5);
        let (j, dt) = (0.7, 0.05);
        let mut q = q0;
        drift_isotropic(SubRotation::Exact, &mut q, &l, j, dt);
        let expected = Rotation::from_scaled_axis(l * (dt / j)) * q0;
        let angle = q.angle_to(&expected);
        assert!(
            angle < 1e-15,
            "L = {l:?}, J = {j}, Δt = {dt}: angle to the closed form {angle:e}, tolerance 1e-15"
        );
    }

    #[test]
    fn cayley_turn_is_the_rotation_by_four_atan_of_a_quarter_angle() {
        let q0 = Rotation::from_scaled_axis(Vector::new(-0.1, 0.3, 0.2));
        let l = Vector::new(2.0, 0.5, -1.0);
        let (j, dt) = (0.4, 0.1);
        let mut q = q0;
        drift_isotropic(SubRotation::Cayley, &mut q, &l, j, dt);
        let theta = dt * l.norm() / j;
        let expected = Rotation::from_axis_angle(
            &nalgebra::Unit::new_normalize(l),
            4.0 * (theta / 4.0).atan(),
        ) * q0;
        let angle = q.angle_to(&expected);
        assert!(
            angle < 1e-15,
            "θ = {theta}: angle to the Cayley closed form {angle:e}, tolerance 1e-15"
        );
    }

    #[test]
    fn splitting_of_an_isotropic_body_converges_to_the_single_turn_at_second_order() {
        // The splitting is second order, the single turn exact: over a fixed time their orientations differ
        // by O(Δt²), i.e. the difference falls by ~4 when Δt halves.
        let j = 0.25;
        let inertia = PrincipalInertia::new(Vector::new(j, j, j)).unwrap();
        let l = Vector::new(0.8, -0.6, 0.5);
        let q0 = Rotation::from_scaled_axis(Vector::new(0.2, 0.1, -0.7));
        let difference = |steps: usize| {
            let dt = 1.0 / steps as Real;
            let (mut q_split, mut q_turn) = (q0, q0);
            for _ in 0..steps {
                let mut lb = q_split.inverse_transform_vector(&l);
                drift_splitting(SubRotation::Exact, &mut q_split, &mut lb, &inertia, dt);
                drift_isotropic(SubRotation::Exact, &mut q_turn, &l, j, dt);
            }
            q_split.angle_to(&q_turn)
        };
        let (coarse, fine) = (difference(50), difference(100));
        let order = (coarse / fine).log2();
        assert!(
            coarse > 1e-8 && (order - 2.0).abs() < 0.1,
            "splitting vs single turn: {coarse:e} at Δt = 1/50, {fine:e} at 1/100, fitted order {order} (expected 2 ± 0.1)"
        );
    }
}
