//! Translation: velocity Verlet (the synchronized form of leapfrog) for m ü + c u̇ + F_c = F_a
//! (paper eq. 6), with gravity and optional global viscous damping.
//!
//! One step of length Δt is: [`first_half_kick`] with the forces at t_n, [`drift_position`] over Δt,
//! (the caller evaluates the forces at t_{n+1}), [`second_half_kick`]. Without damping this is exactly the
//! leapfrog / central-difference scheme (v_{n+1/2} = v_{n−1/2} + Δt a_n, x_{n+1} = x_n + Δt v_{n+1/2}):
//! second order, symplectic, time-reversible, exact for a constant force.
//!
//! Damping −c u̇ is taken explicitly in the first half kick and implicitly in the second:
//! v_{n+1/2} = v_n + ½Δt (F_n − c v_n)/m and v_{n+1} = (v_{n+1/2} + ½Δt F_{n+1}/m) / (1 + ½Δt c/m). The two
//! halves are adjoint to each other, so their composition treats the damping term by the trapezoidal rule
//! and the step stays second order; for a free body v decays by ((1 − ½Δt c/m)/(1 + ½Δt c/m)) per step, the
//! (1,1) Padé approximant of e^{−cΔt/m}, which is unconditionally stable and never reverses the velocity.

use crate::dynamics::body::RigidBody;
use crate::math::{Point, Real, Vector};

/// Parameters of the translational update shared by all bodies.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TranslationParams {
    /// Gravitational acceleration g (m/s²), world frame.
    pub gravity: Vector,
    /// Global viscous damping of eq. 6.
    pub damping: ViscousDamping,
}

/// The viscous damping term c u̇ of eq. 6.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ViscousDamping {
    /// No damping.
    None,
    /// The same coefficient c (kg/s) for every body, as written in eq. 6.
    Coefficient(Real),
    /// c = α m with the rate α (1/s): the same relaxation time 1/α for bodies of any mass.
    MassProportional(Real),
}

impl ViscousDamping {
    /// The coefficient c (kg/s) for a body of mass `mass`.
    pub fn coefficient(&self, mass: Real) -> Real {
        match *self {
            Self::None => 0.0,
            Self::Coefficient(c) => c,
            Self::MassProportional(rate) => rate * mass,
        }
    }
}

/// v ← v + h (F + m g − c v) / m, with F the resultant of contact and applied forces (N) at the start of the
/// step and h = Δt/2.
pub fn first_half_kick(body: &mut RigidBody, force: &Vector, params: &TranslationParams, h: Real) {
    let c = params.damping.coefficient(body.mass);
    body.velocity = first_half_kick_velocity(
        &body.velocity,
        force,
        body.mass,
        &params.gravity,
        Some(c),
        h,
    );
}

/// x ← x + Δt v.
pub fn drift_position(body: &mut RigidBody, dt: Real) {
    body.position = drifted_position(&body.position, &body.velocity, dt);
}

/// v ← (v + h (F + m g)/m) / (1 + h c/m), with F the resultant force at the end of the step and h = Δt/2.
pub fn second_half_kick(body: &mut RigidBody, force: &Vector, params: &TranslationParams, h: Real) {
    let c = params.damping.coefficient(body.mass);
    body.velocity = second_half_kick_velocity(
        &body.velocity,
        force,
        body.mass,
        &params.gravity,
        Some(c),
        h,
    );
}

/// The velocity (m/s) after the first half kick: v + h (F/m + g − (c/m) v), for a body of mass `mass` (kg)
/// under the force F (N) at the start of the step, gravity g (m/s²) and h = Δt/2. Every path that
/// integrates a body calls it: the bodies' [`first_half_kick`] and the flat sphere layout's drift pass.
///
/// `damping` is c (kg/s), or `None` where the path has no global damping: the term is then left out, which
/// gives the value of c = 0 (x − (0/m)·v = x for the finite sums a step forms) with one division, one
/// multiplication and one subtraction fewer per component.
#[inline(always)]
pub fn first_half_kick_velocity(
    velocity: &Vector,
    force: &Vector,
    mass: Real,
    gravity: &Vector,
    damping: Option<Real>,
    h: Real,
) -> Vector {
    match damping {
        Some(c) => velocity + h * (force / mass + gravity - (c / mass) * velocity),
        None => velocity + h * (force / mass + gravity),
    }
}

/// The velocity (m/s) after the second half kick: (v + h (F/m + g)) / (1 + h c/m), with F the force (N) at
/// the end of the step; `damping` as in [`first_half_kick_velocity`] (`None`: no division by 1).
#[inline(always)]
pub fn second_half_kick_velocity(
    velocity: &Vector,
    force: &Vector,
    mass: Real,
    gravity: &Vector,
    damping: Option<Real>,
    h: Real,
) -> Vector {
    let kicked = velocity + h * (force / mass + gravity);
    match damping {
        Some(c) => kicked / (1.0 + h * c / mass),
        None => kicked,
    }
}

/// The position (m) after the drift: x + Δt v.
#[inline(always)]
pub fn drifted_position(position: &Point, velocity: &Vector, dt: Real) -> Point {
    position + dt * velocity
}
