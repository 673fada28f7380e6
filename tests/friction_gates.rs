//! Gate (cube part): a cube resting on an incline sticks for tan θ < μ and slides with
//! a = g (sin θ − μ cos θ) otherwise, also close to the friction angle (tan θ = 0.9 μ). The incline is a horizontal wall with gravity tilted by θ (the same
//! problem in the wall's frame); contact through the contact core's polyhedron–plane path, linear normal
//! law with restitution damping, incremental tangential spring with Coulomb cap, body integrator.

use polydem::math::Real;
use polydem_validation::sim::incline::{slide, DENSITY, G, SIDE, STIFFNESS};

/// Sticking well below the friction angle: the only motion is the elastic stretch of the tangential spring,
/// F_t/k_t ≤ μ m g cos θ / k_t (≈ 5e-6 m here); bound 10× that. Measured: 5.0e-6 m.
#[test]
fn cube_sticks_well_below_the_friction_angle() {
    check_sticking(0.5);
}

/// Close to the friction angle (tan θ = 0.9 μ). With the former deepest-vertex wall law the cube crept
/// 5.6e-4 m in 0.5 s, 12× the bound (3.7e-3 m when the plane path used a depth-weighted centroid): the
/// single force point jumped between the corners of the resting face, the cube rocked about it barely
/// damped and the Coulomb cap was reached in the dips of the normal force. With the smoothed wall depth
/// (`src/contact/wall_depth.rs`, band = the static overlap) the force point moves continuously over the
/// face: measured 2.8e-5 m, 0.61 of the bound.
#[test]
fn cube_sticks_close_to_the_friction_angle() {
    check_sticking(0.9);
}

fn check_sticking(ratio: Real) {
    let mu = 0.5;
    let theta = (ratio * mu as Real).atan();
    let run = slide(theta, mu, 0.5);
    let stretch = mu * DENSITY * SIDE.powi(3) * G * theta.cos() / STIFFNESS;
    assert!(
        run.displacement.abs() < 10.0 * stretch,
        "tan θ = {ratio} μ: the cube moved {} m down the slope in 0.5 s, bound 10 × spring stretch = {} m",
        run.displacement,
        10.0 * stretch
    );
    assert!(
        run.max_tilt < 1e-3,
        "tan θ = {ratio} μ: the cube tilted by {} rad",
        run.max_tilt
    );
}

#[test]
fn cube_slides_with_the_coulomb_acceleration_above_the_friction_angle() {
    let mu = 0.5;
    for ratio in [1.3, 1.8] {
        let theta = (ratio * mu as Real).atan();
        let run = slide(theta, mu, 0.5);
        let expected = G * (theta.sin() - mu * theta.cos());
        let error = (run.acceleration - expected).abs() / expected;
        println!(
            "tan θ = {ratio} μ: a = {}, expected {expected}, relative error {error:e}, tilt {}",
            run.acceleration, run.max_tilt
        );
        assert!(
            error < 0.01,
            "tan θ = {ratio} μ (θ = {theta} rad): sliding acceleration {} m/s², expected g(sin θ − μ cos θ) = {expected} m/s², relative error {error:e}, tolerance 1 %",
            run.acceleration
        );
        assert!(
            run.max_tilt < 1e-2,
            "tan θ = {ratio} μ: the cube tilted by {} rad while sliding",
            run.max_tilt
        );
    }
}
