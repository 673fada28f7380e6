//! Contact laws: pure functions from contact geometry and relative velocity to forces, torques and energy
//! terms (paper section 2.3), composed by slot in a [`ContactModel`] `{ normal, damping, tangential }`.
//!
//! - [`normal`]: the power law f_n = k_n δ^n of paper eq. 5 (n = 1 linear, n = 3/2 Hertz-type) and its
//!   elastic potential k_n δ^(n+1)/(n+1).
//! - [`damping`]: a viscous normal damping f_d = ζ̂ √(m* k_n) δ^((n−1)/2) δ̇ whose coefficient ζ̂ is set from a
//!   coefficient of restitution, exactly for every exponent n (a change of variables turns the impact into a
//!   linear damped oscillator; the restitution is independent of the impact speed).
//! - [`tangential`]: an incremental spring with a Coulomb cap μ|F_n|; the spring (history) is stored by the
//!   caller and rotated into the current tangent plane here.
//! - [`hertz_mindlin`]: the sphere laws parameterised as YADE and LIGGGHTS do (E, ν, e, μ → k_n, k_t,
//!   damping), and the linear spring–dashpot.
//! - [`model`]: the slot composition, evaluated on a [`crate::contact::ContactGeometry`]; [`prepared`]:
//!   the same with the constants of one contact formed once.
//!
//! Sign conventions: the contact normal n points from body A to body B; forces are reported as the force on
//! B (the force on A is its opposite); the relative velocity is v_B − v_A at the contact point c_M, so the
//! overlap rate is δ̇ = −(v_B − v_A)·n.

pub mod damping;
pub mod hertz_mindlin;
pub mod model;
pub mod normal;
pub mod pair;
pub mod prepared;
pub mod tangential;

pub use damping::DampingLaw;
pub use model::{ContactKinematics, ContactModel, ContactResponse};
pub use normal::{NormalLaw, RadiusScaling};
pub use prepared::PreparedModel;
pub use tangential::{SpringRotation, TangentialHistory, TangentialLaw};

/// Invalid law parameters.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum LawError {
    /// A parameter is not finite or lies outside its valid range.
    #[error("{name} = {value} is outside its valid range {range}")]
    OutOfRange {
        /// Name of the parameter.
        name: &'static str,
        /// The value given (in the parameter's SI unit).
        value: crate::math::Real,
        /// The valid range, as text.
        range: &'static str,
    },
}

/// Checks that a parameter is finite and inside `lo..=hi` (or `lo < value` when `open_low`).
pub(crate) fn check_range(
    name: &'static str,
    value: crate::math::Real,
    lo: crate::math::Real,
    hi: crate::math::Real,
    open_low: bool,
    range: &'static str,
) -> Result<(), LawError> {
    let low_ok = if open_low { value > lo } else { value >= lo };
    if value.is_finite() && low_ok && value <= hi {
        Ok(())
    } else {
        Err(LawError::OutOfRange { name, value, range })
    }
}
