//! The DLM symmetric splitting of the free rigid body (paper eqs. 20–23); derivation in the parent module.

use super::SubRotation;
use crate::dynamics::body::PrincipalInertia;
use crate::math::{Real, Rotation, Vector};
use nalgebra::Quaternion;

/// One sub-rotation: the flow of T_i = L̄_i²/(2J̄_i) over the time `h` about body axis `axis` (0, 1, 2).
///
/// q ← q ⊗ q_i(θ), L̄ ← R_i(−θ) L̄ with θ = h L̄_i / J̄_i (or the Cayley angle 4 atan(θ/4)).
///
/// # Panics
/// If `axis` is not 0, 1 or 2 (a programming error, never user input).
pub fn sub_rotation(
    form: SubRotation,
    axis: usize,
    orientation: &mut Rotation,
    angular_momentum_body: &mut Vector,
    inertia: &PrincipalInertia,
    h: Real,
) {
    match axis {
        0 => sub_rotation_about::<0>(form, orientation, angular_momentum_body, inertia, h),
        1 => sub_rotation_about::<1>(form, orientation, angular_momentum_body, inertia, h),
        2 => sub_rotation_about::<2>(form, orientation, angular_momentum_body, inertia, h),
        _ => panic!("body axis index {axis} is not 0, 1 or 2"),
    }
}

/// [`sub_rotation`] with the axis known at compile time (the index arithmetic folds away).
#[inline]
fn sub_rotation_about<const AXIS: usize>(
    form: SubRotation,
    orientation: &mut Rotation,
    angular_momentum_body: &mut Vector,
    inertia: &PrincipalInertia,
    h: Real,
) {
    let axis = AXIS;
    let theta = h * angular_momentum_body[axis] / inertia.0[axis];
    // (w, s) = (cos, sin) of half the rotation angle.
    let (w, s) = match form {
        SubRotation::Cayley => {
            // Paper eq. 21 with φ = ½ h L̄_i / J̄_i = θ/2.
            let phi = 0.5 * theta;
            let quarter = 0.25 * phi * phi;
            let reciprocal = 1.0 / (1.0 + quarter);
            ((1.0 - quarter) * reciprocal, phi * reciprocal)
        }
        SubRotation::Exact => {
            let (s, w) = (0.5 * theta).sin_cos();
            (w, s)
        }
    };
    // q ← q ⊗ (w, s e_i), written out for the sparse right factor: with q = (q₀, v),
    // q ⊗ (w, s e_i) = (w q₀ − s v_i, w v + s (q₀ e_i + v × e_i)).
    let q = orientation.quaternion();
    let (q0, v) = (q.w, q.imag());
    let mut v_cross_e = Vector::zeros();
    v_cross_e[(axis + 1) % 3] = v[(axis + 2) % 3];
    v_cross_e[(axis + 2) % 3] = -v[(axis + 1) % 3];
    let mut imaginary = w * v + s * v_cross_e;
    imaginary[axis] += s * q0;
    *orientation = Rotation::new_unchecked(Quaternion::from_parts(w * q0 - s * v[axis], imaginary));
    // Rotate L̄ by −angle about the same axis: cos and sin of the full angle from the half-angle pair.
    let cos_full = w * w - s * s;
    let sin_full = 2.0 * w * s;
    let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
    let (lj, lk) = (angular_momentum_body[j], angular_momentum_body[k]);
    angular_momentum_body[j] = cos_full * lj + sin_full * lk;
    angular_momentum_body[k] = -sin_full * lj + cos_full * lk;
}

/// The symmetric composition of eq. 23 over a step `dt`: axes 1, 2 for dt/2, axis 3 for dt, axes 2, 1 for
/// dt/2; the quaternion is renormalised once at the end (it drifts from unit length only by round-off).
pub fn drift_splitting(
    form: SubRotation,
    orientation: &mut Rotation,
    angular_momentum_body: &mut Vector,
    inertia: &PrincipalInertia,
    dt: Real,
) {
    let half = 0.5 * dt;
    sub_rotation_about::<0>(form, orientation, angular_momentum_body, inertia, half);
    sub_rotation_about::<1>(form, orientation, angular_momentum_body, inertia, half);
    sub_rotation_about::<2>(form, orientation, angular_momentum_body, inertia, dt);
    sub_rotation_about::<1>(form, orientation, angular_momentum_body, inertia, half);
    sub_rotation_about::<0>(form, orientation, angular_momentum_body, inertia, half);
    orientation.renormalize_fast();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sub_rotation_keeps_the_world_momentum_and_the_axis_component() {
        let inertia = PrincipalInertia::new(Vector::new(1.0, 2.0, 3.0)).unwrap();
        for form in [SubRotation::Cayley, SubRotation::Exact] {
            for axis in 0..3 {
                let mut q = Rotation::from_scaled_axis(Vector::new(0.2, 0.5, -0.4));
                let mut lb = Vector::new(0.7, -1.1, 0.4);
                let world_before = q.transform_vector(&lb);
                let axis_component = lb[axis];
                sub_rotation(form, axis, &mut q, &mut lb, &inertia, 0.3);
                let world_after = q.transform_vector(&lb);
                assert!(
                    (world_after - world_before).norm() < 1e-15,
                    "{form:?} axis {axis}: world L {world_before:?} → {world_after:?}"
                );
                assert_eq!(
                    lb[axis], axis_component,
                    "{form:?} axis {axis}: L̄_i changed"
                );
            }
        }
    }

    #[test]
    fn exact_sub_rotation_turns_by_the_expected_angle() {
        // From the identity, a turn about body axis 3 by θ = h L̄₃ / J̄₃ must equal the axis–angle rotation.
        let inertia = PrincipalInertia::new(Vector::new(1.0, 2.0, 4.0)).unwrap();
        let mut q = Rotation::identity();
        let mut lb = Vector::new(0.0, 0.0, 2.0);
        sub_rotation(SubRotation::Exact, 2, &mut q, &mut lb, &inertia, 0.7);
        let expected = Rotation::from_axis_angle(&Vector::z_axis(), 0.7 * 2.0 / 4.0);
        assert!(
            q.angle_to(&expected) < 1e-15,
            "rotation {q:?}, expected {expected:?}"
        );
        // The Cayley form turns by 4 atan(θ/4).
        let mut q = Rotation::identity();
        let mut lb = Vector::new(0.0, 0.0, 2.0);
        sub_rotation(SubRotation::Cayley, 2, &mut q, &mut lb, &inertia, 0.7);
        let theta: Real = 0.35;
        let expected = Rotation::from_axis_angle(&Vector::z_axis(), 4.0 * (theta / 4.0).atan());
        assert!(
            q.angle_to(&expected) < 1e-15,
            "Cayley rotation {q:?}, expected {expected:?}"
        );
    }

    #[test]
    fn splitting_is_time_reversible() {
        // Drift forward, flip the momentum, drift again: back to the start (up to round-off).
        let inertia = PrincipalInertia::new(Vector::new(1.0, 2.0, 3.0)).unwrap();
        for form in [SubRotation::Cayley, SubRotation::Exact] {
            let q0 = Rotation::from_scaled_axis(Vector::new(-0.3, 0.8, 0.1));
            let l0 = Vector::new(1.0, 0.5, -2.0);
            let (mut q, mut lb) = (q0, l0);
            for _ in 0..100 {
                drift_splitting(form, &mut q, &mut lb, &inertia, 0.05);
            }
            lb = -lb;
            for _ in 0..100 {
                drift_splitting(form, &mut q, &mut lb, &inertia, 0.05);
            }
            let angle = q.angle_to(&q0);
            let momentum_error = (-lb - l0).norm() / l0.norm();
            assert!(
                angle < 1e-12 && momentum_error < 1e-12,
                "{form:?}: after forward + reversed run, angle to start {angle:e}, momentum error {momentum_error:e}, tolerance 1e-12"
            );
        }
    }
}
