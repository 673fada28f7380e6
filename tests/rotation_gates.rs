//! Gates of the rotation integrator (torque-free precession, unit-test part): the DLM
//! splitting of paper eqs. 18–25 against the exact torque-free solutions of `polydem::dynamics::analytic`.

use polydem::dynamics::analytic::{AsymmetricTop, Regime, SymmetricTop};
use polydem::dynamics::rotation::drift_rotation;
use polydem::dynamics::{
    Integrator, PrincipalInertia, RigidBody, RotationScheme, SubRotation, TranslationParams,
    ViscousDamping,
};
use polydem::math::{Point, Real, Rotation, Vector};
use polydem_validation::stats::fitted_order;

const CAYLEY: RotationScheme = RotationScheme::Splitting {
    sub_rotation: SubRotation::Cayley,
};
const EXACT: RotationScheme = RotationScheme::Splitting {
    sub_rotation: SubRotation::Exact,
};

/// An asymmetric body (principal moments of a 1 × 0.8 × 0.5 box of unit mass, sorted ascending) spinning
/// mostly about its major axis with a generic tilt.
fn asymmetric_case() -> (Vector, Vector, Rotation) {
    let (a, b, c): (Real, Real, Real) = (1.0, 0.8, 0.5);
    let inertia = Vector::new(b * b + c * c, a * a + c * c, a * a + b * b) / 12.0;
    (
        inertia,
        Vector::new(0.4, -0.7, 2.0),
        Rotation::from_scaled_axis(Vector::new(0.3, -0.5, 0.8)),
    )
}

fn body(inertia: Vector, omega_body: Vector, orientation: Rotation) -> RigidBody {
    let mut body = RigidBody::new_dynamic(
        Point::origin(),
        1.0,
        PrincipalInertia::new(inertia).unwrap(),
    )
    .unwrap();
    body.orientation = orientation;
    body.set_angular_velocity(&orientation.transform_vector(&omega_body));
    body
}

fn integrator(rotation: RotationScheme) -> Integrator {
    Integrator {
        translation: TranslationParams {
            gravity: Vector::zeros(),
            damping: ViscousDamping::None,
        },
        rotation,
    }
}

#[test]
fn splitting_conserves_world_angular_momentum_to_round_off() {
    let (inertia, omega0, q0) = asymmetric_case();
    let top = AsymmetricTop::new(inertia, omega0, q0).unwrap();
    let dt = top.period() / 200.0;
    for scheme in [CAYLEY, EXACT] {
        // The splitting map itself, on (q, L̄): R(q) L̄ stays fixed up to round-off, since every sub-rotation
        // turns q and L̄ consistently. The rounding repeats coherently along the periodic body-frame motion, so
        // it grows linearly: the bound is one unit of 1e-16 per step (a scheme error would be O(dt³) per step,
        // ~1e-7 here). The measured value is in the precession report (section Notes).
        let inertia_p = PrincipalInertia::new(inertia).unwrap();
        let (mut q, mut lb) = (q0, omega0.component_mul(&inertia));
        let l0 = q.transform_vector(&lb);
        let mut worst: Real = 0.0;
        let steps = 100_000;
        for step in 0..steps {
            drift_rotation(scheme, &mut q, &mut lb, &inertia_p, dt);
            if step % 100 == 99 {
                worst = worst.max((q.transform_vector(&lb) - l0).norm() / l0.norm());
            }
        }
        let bound = 1e-16 * steps as Real;
        assert!(
            worst <= bound,
            "{scheme:?}: max relative drift of R(q)L̄ over {steps} steps (dt = T/200) = {worst:e}, round-off bound {bound:e}"
        );
        // The integrated body: world L is its state and each drift keeps it; over 1e6 steps it must not move.
        let mut b = body(inertia, omega0, q0);
        let it = integrator(scheme);
        let l0 = b.angular_momentum;
        for _ in 0..1_000_000 {
            it.step_free(&mut b, dt);
        }
        let drift = (b.angular_momentum - l0).norm() / l0.norm();
        assert!(
            drift <= 1e-12,
            "{scheme:?}: world-L drift over 1e6 integrator steps {drift:e}, tolerance 1e-12"
        );
    }
}

#[test]
fn splitting_energy_error_is_bounded_without_drift_over_a_million_steps() {
    let (inertia, omega0, q0) = asymmetric_case();
    let top = AsymmetricTop::new(inertia, omega0, q0).unwrap();
    let dt = top.period() / 200.0;
    let steps = 1_000_000;
    for scheme in [CAYLEY, EXACT] {
        let mut b = body(inertia, omega0, q0);
        let it = integrator(scheme);
        let e0 = b.rotational_kinetic_energy();
        let (mut first, mut last): (Real, Real) = (0.0, 0.0);
        for step in 0..steps {
            it.step_free(&mut b, dt);
            let error = ((b.rotational_kinetic_energy() - e0) / e0).abs();
            if step < steps / 10 {
                first = first.max(error);
            } else if step >= steps - steps / 10 {
                last = last.max(error);
            }
        }
        // Bounded: the error amplitude of a second-order method at dt = T/200 is O((2π/200)²) ≈ 1e-3 times a
        // problem constant; no drift: the amplitude in the last tenth of the run is not larger than in the first
        // tenth (each tenth spans 500 periods, so both maxima sample the full oscillation).
        assert!(
            first < 1e-3,
            "{scheme:?}: energy error amplitude {first:e} at dt = T/200, bound 1e-3"
        );
        assert!(
            last <= 1.05 * first,
            "{scheme:?}: energy error grew from {first:e} (first 1e5 steps) to {last:e} (last 1e5 steps): drift"
        );
    }
}

#[test]
fn splitting_angular_velocity_converges_at_second_order_to_the_elliptic_solution() {
    let (inertia, omega0, q0) = asymmetric_case();
    let top = AsymmetricTop::new(inertia, omega0, q0).unwrap();
    let t_end = 3.0 * top.period();
    let reference = top.omega_body(t_end);
    let reference_q = top.orientation(t_end);
    for scheme in [CAYLEY, EXACT] {
        let (mut dts, mut omega_errors, mut angle_errors) = (vec![], vec![], vec![]);
        for per_period in [100, 200, 400, 800, 1600] {
            let steps = 3 * per_period;
            let dt = t_end / steps as Real;
            let mut b = body(inertia, omega0, q0);
            let it = integrator(scheme);
            for _ in 0..steps {
                it.step_free(&mut b, dt);
            }
            dts.push(dt);
            omega_errors.push((b.angular_velocity_body() - reference).norm() / reference.norm());
            angle_errors.push(b.orientation.angle_to(&reference_q));
        }
        let order = fitted_order(&dts, &omega_errors);
        assert!(
            (order - 2.0).abs() <= 0.2,
            "{scheme:?}: fitted order of ω̄(t) error {order}, expected 2 ± 0.2; dt {dts:?}, errors {omega_errors:?}"
        );
        let order_q = fitted_order(&dts, &angle_errors);
        assert!(
            (order_q - 2.0).abs() <= 0.2,
            "{scheme:?}: fitted order of orientation error {order_q}, expected 2 ± 0.2; errors {angle_errors:?}"
        );
    }
}

#[test]
fn splitting_matches_the_symmetric_top_closed_form_at_second_order() {
    let inertia = Vector::new(0.3, 0.3, 0.12);
    let omega0 = Vector::new(0.5, -0.2, 4.0);
    let q0 = Rotation::from_scaled_axis(Vector::new(-0.2, 0.6, 0.1));
    let top = SymmetricTop::new(inertia, omega0, q0).unwrap();
    let t_end = 5.0;
    let (mut dts, mut errors) = (vec![], vec![]);
    for steps in [500, 1000, 2000, 4000] {
        let dt = t_end / steps as Real;
        let mut b = body(inertia, omega0, q0);
        let it = integrator(CAYLEY);
        for _ in 0..steps {
            it.step_free(&mut b, dt);
        }
        let omega_error =
            (b.angular_velocity_body() - top.omega_body(t_end)).norm() / omega0.norm();
        let angle_error = b.orientation.angle_to(&top.orientation(t_end));
        dts.push(dt);
        errors.push(omega_error.max(angle_error));
    }
    let order = fitted_order(&dts, &errors);
    assert!(
        (order - 2.0).abs() <= 0.2,
        "symmetric top: fitted order {order}, expected 2 ± 0.2; dt {dts:?}, errors {errors:?}"
    );
    assert!(
        errors[3] < 1e-4,
        "symmetric top error {} at dt = {}, tolerance 1e-4",
        errors[3],
        dts[3]
    );
}

/// Times at which ω̄₂ changes sign, by linear interpolation between steps.
fn sign_changes_of_omega2(
    scheme: RotationScheme,
    top_inputs: (Vector, Vector, Rotation),
    dt: Real,
    t_end: Real,
) -> Vec<Real> {
    let (inertia, omega0, q0) = top_inputs;
    let mut b = body(inertia, omega0, q0);
    let it = integrator(scheme);
    let mut crossings = vec![];
    let mut previous = b.angular_velocity_body()[1];
    let steps = (t_end / dt) as usize;
    for step in 0..steps {
        it.step_free(&mut b, dt);
        let current = b.angular_velocity_body()[1];
        if previous != 0.0 && previous.signum() != current.signum() {
            let fraction = previous / (previous - current);
            crossings.push((step as Real + fraction) * dt);
        }
        previous = current;
    }
    crossings
}

#[test]
fn intermediate_axis_flip_period_matches_four_k_over_lambda() {
    // Spin about the intermediate axis with a small perturbation: the Dzhanibekov flip. ω̄₂ changes sign
    // twice per period 4K(m)/λ.
    let (inertia, _, q0) = asymmetric_case();
    let omega0 = Vector::new(0.01, 3.0, 0.02);
    let top = AsymmetricTop::new(inertia, omega0, q0).unwrap();
    let period = top.period();
    assert!(
        top.parameter > 0.99,
        "not near the separatrix: m = {}",
        top.parameter
    );
    let mut measured_errors = vec![];
    for per_period in [500.0, 1000.0, 2000.0] {
        let dt = period / per_period;
        let crossings = sign_changes_of_omega2(CAYLEY, (inertia, omega0, q0), dt, 4.2 * period);
        assert!(
            crossings.len() >= 8,
            "only {} sign changes of ω̄₂ in 4.2 periods",
            crossings.len()
        );
        // Every other crossing is one full period apart.
        let measured = (crossings[crossings.len() - 1] - crossings[crossings.len() - 7]) / 3.0;
        measured_errors.push(((measured - period) / period).abs());
    }
    // At dt = T/2000 the period error is at most 1e-4 relative, and it decreases with dt.
    assert!(
        measured_errors[2] < 1e-4,
        "flip period error {} (relative) at dt = T/2000, tolerance 1e-4; analytic 4K/λ = {period} s (m = {}, {:?})",
        measured_errors[2],
        top.parameter,
        top.regime
    );
    assert!(
        measured_errors[2] < measured_errors[0],
        "flip period error does not decrease with dt: {measured_errors:?}"
    );
    let _ = Regime::AboutAxis1;
}

#[test]
fn explicit_euler_drifts_where_the_splitting_does_not() {
    let (inertia, omega0, q0) = asymmetric_case();
    let top = AsymmetricTop::new(inertia, omega0, q0).unwrap();
    let dt = top.period() / 200.0;
    let steps = 2_000;
    let run = |scheme: RotationScheme| {
        let mut b = body(inertia, omega0, q0);
        let (e0, l0) = (b.rotational_kinetic_energy(), b.angular_momentum);
        let it = integrator(scheme);
        let mut energy_error = vec![];
        for _ in 0..steps {
            it.step_free(&mut b, dt);
            energy_error.push((b.rotational_kinetic_energy() - e0) / e0);
        }
        let momentum_error = (b.angular_momentum - l0).norm() / l0.norm();
        (energy_error, momentum_error)
    };
    let (euler_energy, euler_momentum) = run(RotationScheme::ExplicitEuler);
    let (split_energy, split_momentum) = run(CAYLEY);
    let euler_mid = euler_energy[steps / 2 - 1];
    let euler_end = euler_energy[steps - 1];
    // Explicit Euler gains energy monotonically (its amplification factor exceeds 1): the error at the end
    // is about twice the error at half time, and orders of magnitude above the splitting's bounded error.
    assert!(
        euler_end > 1.5 * euler_mid && euler_mid > 0.0,
        "explicit Euler energy error at T/2 {euler_mid:e}, at T {euler_end:e}: expected secular growth"
    );
    let split_max = split_energy.iter().fold(0.0 as Real, |m, e| m.max(e.abs()));
    assert!(
        euler_end > 100.0 * split_max,
        "explicit Euler energy error {euler_end:e} vs splitting max {split_max:e}: expected ≥ 100×"
    );
    assert!(
        euler_momentum > 1e6 * split_momentum.max(1e-16),
        "explicit Euler world-L error {euler_momentum:e} vs splitting {split_momentum:e}"
    );
}

#[test]
fn drift_rotation_leaves_a_unit_quaternion() {
    let (inertia, omega0, q0) = asymmetric_case();
    let inertia_p = PrincipalInertia::new(inertia).unwrap();
    for scheme in [
        CAYLEY,
        EXACT,
        RotationScheme::ExplicitEuler,
        RotationScheme::RungeKutta4,
    ] {
        let mut q = q0;
        let mut l = omega0.component_mul(&inertia);
        for _ in 0..10_000 {
            drift_rotation(scheme, &mut q, &mut l, &inertia_p, 0.01);
        }
        let norm = q.quaternion().norm();
        assert!(
            (norm - 1.0).abs() < 1e-14,
            "{scheme:?}: |q| = {norm} after 1e4 steps"
        );
    }
}
