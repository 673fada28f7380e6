//! Rotation of a rigid body: the symplectic splitting integrator of the paper (section 3.2, eqs. 18–25),
//! after Dullweber, Leimkuhler & McLachlan (1997), "Symplectic splitting methods for rigid body molecular
//! dynamics", J. Chem. Phys. 107:5840 ("DLM"), and simpler schemes kept for comparison.
//!
//! # State and frames
//! The orientation q is the body → world rotation (paper eq. 16: R(q, v) = q v q⁻¹ maps body to world). The
//! world angular momentum about the centre of mass is L = R(q) J̄ R(q)ᵀ ω (eq. 18), the body-frame momentum
//! L̄ = R(q)ᵀ L (eq. 19), and ω̄ = J̄⁻¹ L̄ (eq. 25). Torque-free, L is constant and
//! q̇ = ½ q ⊗ (0, ω̄), L̄̇ = L̄ × ω̄ (Euler's equations, eq. 10, written for L̄).
//!
//! # Derivation of the sub-rotations (the garbled eq. 22)
//! The free rigid body has the Hamiltonian T = T₁ + T₂ + T₃ with T_i = L̄_i² / (2 J̄_i). DLM split T into
//! these three terms and compose their exact flows. The flow of T_i alone has body angular velocity
//! ω̄ = (L̄_i / J̄_i) e_i, and L̄_i is constant along it (a rotation about e_i leaves the i-th component of L̄
//! unchanged), so over a time h the body turns about its own axis e_i by the fixed angle
//! θ_i = h L̄_i / J̄_i:
//!
//! ```text
//!   q   ← q ⊗ q_i(θ_i),            q_i(θ) = (cos θ/2, sin θ/2 e_i)   (right product: a body-axis turn)
//!   L̄   ← R_i(−θ_i) L̄              (the world L is fixed, so its body components turn the other way)
//! ```
//!
//! since L̄(h) = R(q ⊗ q_i)ᵀ L = R_i(θ)ᵀ R(q)ᵀ L = R_i(−θ) L̄(0). This is eq. 22 read correctly: the update
//! multiplies the orientation by q_i on the right and rotates L̄ by the conjugate q_i⁻¹.
//!
//! The paper evaluates q_i with the Cayley form of eqs. 20–21: with φ_i = ½ h L̄_i / J̄_i = θ_i / 2,
//! q_i = (c, s e_i), c = (1 − φ²/4)/(1 + φ²/4), s = φ/(1 + φ²/4). This is an exact unit quaternion, the
//! rotation by the angle θ̃ = 4 atan(θ/4) = θ − θ³/48 + O(θ⁵). Because θ̃ still depends on L̄_i only (which the
//! sub-rotation leaves invariant), the Cayley sub-step is the exact flow of a modified Hamiltonian
//! T̃_i(L̄_i) with dT̃_i/dL̄_i = θ̃/h, so it keeps every structural property of the exact version
//! (symplectic, |L̄| preserved, time-reversible because θ̃ is odd in L̄_i); only the energy it conserves
//! approximately is a modified one. [`SubRotation`] selects the Cayley or the exact (cos, sin) form; both are
//! second order and the validation report compares them.
//!
//! # The composition (eq. 23)
//! q, L̄ ← Φ₁(h/2) ∘ Φ₂(h/2) ∘ Φ₃(h) ∘ Φ₂(h/2) ∘ Φ₁(h/2): axis 1 half, axis 2 half, axis 3 full, axis 2 half,
//! axis 1 half. It is a symmetric Strang composition of exact (or modified-exact) Hamiltonian flows, hence
//! second order, symplectic (a Poisson map preserving the Casimir |L|), and time-reversible. World angular
//! momentum is conserved up to round-off because each sub-step rotates q and L̄ consistently; energy is not
//! conserved exactly but its error stays bounded (oscillates without drift) as for any symplectic method.
//!
//! # Torque kicks and leapfrog
//! Eq. 18 applies a full kick L ← L + Δt p_n and then drifts with that L: a kick–drift (symplectic Euler)
//! step in which ω_n is really the half-step value ω_{n−1/2}, exactly the central-difference / leapfrog
//! arrangement of the translation (velocities at half steps, positions at whole steps), so L is used at the
//! half step t_{n+1/2} in the drift. We write the same method in its synchronized velocity-Verlet form:
//! half kick L ← L + ½Δt p_n, drift Δt, forces at t_{n+1}, half kick L ← L + ½Δt p_{n+1}. The orientations
//! q_n are identical to the paper's leapfrog sequence (the two half kicks between drifts add up to eq. 18's
//! full kick); the synchronized form also gives ω at whole steps, which the energy ledger needs.
//!
//! # Schemes kept for comparison
//! - [`RotationScheme::ExplicitEuler`]: the textbook first-order update of many DEM codes, explicit Euler on
//!   q̇ = ½ q ⊗ ω̄ (renormalised) and on Euler's equations. Neither energy nor world angular momentum is
//!   conserved; both drift linearly in time.
//! - [`RotationScheme::RungeKutta4`]: classical fourth-order Runge–Kutta on the same ODE with the quaternion
//!   renormalised after the step. Accurate per step, but neither symplectic nor momentum-conserving: errors
//!   accumulate secularly over long runs.

mod explicit;
mod isotropic;
mod splitting;

pub use explicit::{drift_explicit_euler, drift_runge_kutta4};
pub use isotropic::{drift_isotropic, is_isotropic};
pub use splitting::{drift_splitting, sub_rotation};

use crate::dynamics::body::PrincipalInertia;
use crate::math::{Real, Rotation, Vector};

/// How a sub-rotation about a body axis evaluates its quaternion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SubRotation {
    /// The paper's eqs. 20–21: rotation by 4 atan(θ/4), no trigonometric calls.
    Cayley,
    /// Rotation by exactly θ = h L̄_i / J̄_i (cos and sin of θ/2).
    Exact,
}

/// A torque-free rotation update ("drift") over one time step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RotationScheme {
    /// The DLM splitting of paper eqs. 19–25 (default: [`SubRotation::Cayley`] as in the paper).
    Splitting {
        /// How each sub-rotation of the splitting is computed.
        sub_rotation: SubRotation,
    },
    /// Explicit first-order quaternion and Euler-equation update (comparison only).
    ExplicitEuler,
    /// Classical RK4 on the quaternion and Euler equations (comparison only).
    RungeKutta4,
}

impl Default for RotationScheme {
    /// The paper's scheme with its Cayley sub-rotations.
    fn default() -> Self {
        Self::Splitting {
            sub_rotation: SubRotation::Cayley,
        }
    }
}

/// Advances a torque-free rotation by `dt`: updates the body → world orientation `orientation` and the
/// body-frame angular momentum `angular_momentum_body` (kg·m²/s) with the chosen scheme.
pub fn drift_rotation(
    scheme: RotationScheme,
    orientation: &mut Rotation,
    angular_momentum_body: &mut Vector,
    inertia: &PrincipalInertia,
    dt: Real,
) {
    match scheme {
        RotationScheme::Splitting { sub_rotation } => drift_splitting(
            sub_rotation,
            orientation,
            angular_momentum_body,
            inertia,
            dt,
        ),
        RotationScheme::ExplicitEuler => {
            drift_explicit_euler(orientation, angular_momentum_body, inertia, dt)
        }
        RotationScheme::RungeKutta4 => {
            drift_runge_kutta4(orientation, angular_momentum_body, inertia, dt)
        }
    }
}
