//! Normal damping set from a coefficient of restitution.
//!
//! The damping force (on B, along n) is f_d = ζ̂ √(m* k_n) δ^((n−1)/2) δ̇, with the normal law f_n = k_n δ^n,
//! the effective mass m* = m_A m_B/(m_A + m_B) and the overlap rate δ̇. For n = 1 this is the linear dashpot
//! c δ̇ with c = ζ̂ √(m* k_n) = 2ζ√(m* k_n) (ζ the damping ratio); for n = 3/2 it is the Tsuji et al. (1992,
//! Powder Technol. 71:239) form c ∝ δ^(1/4) used by LIGGGHTS' `hertz` and YADE's Hertz–Mindlin.
//!
//! # Restitution: exact for every exponent
//! For a head-on impact, m* δ̈ + ζ̂ √(m* k) δ^a δ̇ + k δ^n = 0 (a = (n−1)/2) with δ(0) = 0, δ̇(0) = v₀. Scaling
//! δ = δ₀ x, t = (δ₀/v₀) s with δ₀ = (m* v₀²/k)^(1/(n+1)) gives x'' + ζ̂ x^a x' + x^n = 0, x(0) = 0, x'(0) = 1:
//! ζ̂ is the only parameter left, so the restitution does not depend on the impact speed, masses or stiffness.
//! Moreover the substitution y = x^((n+1)/2), dτ = x^a ds makes it linear: dy/dτ = ((n+1)/2) x', and
//! d²y/dτ² = ((n+1)/2) x^(−a) x'' = −((n+1)/2) y − ζ̂ dy/dτ (using n − a = (n+1)/2). This is a damped
//! oscillator with ω₀² = (n+1)/2 and damping ratio ζ = ζ̂/√(2(n+1)); the contact starts and ends at y = 0 and
//! x' ∝ dy/dτ there, so e = exp(−πζ/√(1 − ζ²)) exactly, for every n:
//!
//! ```text
//!   ζ̂ = √(2(n+1)) · ζ,   ζ = −ln e / √(π² + ln² e)      (ζ̂ = 2ζ for the linear law, √5 ζ for Hertz)
//! ```
//!
//! For n = 3/2 this is the LIGGGHTS `hertz` damping γ_n = 2√(5/6)|β|√(S_n m*) with β = ln e/√(ln² e + π²) and
//! S_n = 2E*√(R*δ) = (3/2) k_n δ^(1/2) (2√(5/6)·√(3/2) = √5); the √(5/6) factor is the one Antypov & Elliott
//! (2011, EPL 94:50004) derived for this model. YADE's Hertz–Mindlin with `en` uses instead the polynomial fit
//! of Thornton et al. (2013, Powder Technol. 233:30, eqs. B6–B7), an approximation of the same relation. The
//! unit tests check the closed form against a direct numerical integration of the dimensionless impact
//! (agreement ~1e-12) for n = 1, 1.25, 1.5, 2, 3.
//!
//! The contact is taken to end when δ returns to zero, so the total normal force may turn slightly
//! attractive at the very end (as in LIGGGHTS with `limitForce off`); clamping it would change e.

use super::{check_range, LawError};
use crate::math::Real;
use std::f64::consts::PI;

/// The damping slot.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum DampingLaw {
    /// Elastic contact (e = 1).
    None,
    /// f_d = coefficient · √(m* k_n) · δ^((n−1)/2) · δ̇, with the dimensionless coefficient ζ̂ ≥ 0.
    Viscous {
        /// The dimensionless damping coefficient ζ̂ ≥ 0.
        coefficient: Real,
    },
    /// A dashpot of constant coefficient c (N s/m): f_d = c δ̇ whatever the masses and overlap — LIGGGHTS'
    /// `absolute_damping on` (`gamman_abs`) and YADE's `ViscElMat` `cn`. The restitution then depends on
    /// the masses of the pair: e = exp(−π ζ/√(1 − ζ²)), ζ = c/(2√(m* k_n)), for the linear law.
    Dashpot {
        /// The dashpot coefficient c_n ≥ 0 (N s/m).
        coefficient: Real,
    },
}

impl DampingLaw {
    /// A constant dashpot c ≥ 0 (N s/m).
    pub fn dashpot(coefficient: Real) -> Result<Self, LawError> {
        check_range(
            "damping coefficient c_n",
            coefficient,
            0.0,
            Real::MAX,
            false,
            "[0, ∞)",
        )?;
        Ok(Self::Dashpot { coefficient })
    }

    /// The damping that gives the restitution `restitution` for a normal law of exponent `exponent`.
    pub fn from_restitution(exponent: Real, restitution: Real) -> Result<Self, LawError> {
        let coefficient = damping_for_restitution(exponent, restitution)?;
        Ok(if coefficient == 0.0 {
            Self::None
        } else {
            Self::Viscous { coefficient }
        })
    }

    /// The dimensionless coefficient ζ̂ of a viscous law; 0 for the others.
    pub fn viscous_coefficient(&self) -> Real {
        match *self {
            Self::Viscous { coefficient } => coefficient,
            Self::None | Self::Dashpot { .. } => 0.0,
        }
    }

    /// Whether the law is a viscous law or dashpot of coefficient 0, which adds no force: the
    /// `undamped_contacts` skip may replace it by [`DampingLaw::None`] (`crate::world::skips`). False for
    /// `None` itself, which has nothing to skip.
    pub fn has_zero_coefficient(&self) -> bool {
        match *self {
            Self::None => false,
            Self::Viscous { coefficient } | Self::Dashpot { coefficient } => coefficient == 0.0,
        }
    }

    /// The damping force (N, along n on B) at overlap δ, overlap rate δ̇, for the normal law (k_n, n) and
    /// effective mass m*.
    #[inline]
    pub fn force(
        &self,
        stiffness: Real,
        exponent: Real,
        mass: Real,
        overlap: Real,
        overlap_rate: Real,
    ) -> Real {
        self.prepared(stiffness, mass)
            .force(exponent, overlap, overlap_rate)
    }

    /// The law with the constants of one contact (k_n, m*) formed: ζ̂ √(m* k_n) for the viscous law.
    #[inline]
    pub fn prepared(&self, stiffness: Real, mass: Real) -> PreparedDamping {
        match *self {
            Self::None => PreparedDamping::None,
            Self::Viscous { coefficient } => PreparedDamping::Viscous {
                factor: coefficient * (mass * stiffness).sqrt(),
            },
            Self::Dashpot { coefficient } => PreparedDamping::Dashpot { coefficient },
        }
    }
}

/// A [`DampingLaw`] with the constants of one contact formed ([`DampingLaw::prepared`]): what the force
/// needs besides the overlap and its rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PreparedDamping {
    /// No damping.
    None,
    /// f_d = factor · δ^((n−1)/2) · δ̇, factor = ζ̂ √(m* k_n) (N s/m^((n+1)/2)).
    Viscous {
        /// ζ̂ √(m* k_n) of this contact (N s/m^((n+1)/2)).
        factor: Real,
    },
    /// f_d = c_n δ̇.
    Dashpot {
        /// The dashpot coefficient c_n (N s/m).
        coefficient: Real,
    },
}

impl PreparedDamping {
    /// The damping force (N, along n on B) at overlap δ and overlap rate δ̇ for the exponent n of the
    /// normal law; zero for δ ≤ 0.
    #[inline(always)]
    pub fn force(&self, exponent: Real, overlap: Real, overlap_rate: Real) -> Real {
        match *self {
            Self::None => 0.0,
            Self::Viscous { factor } => {
                if overlap <= 0.0 {
                    return 0.0;
                }
                let shape = if exponent == 1.0 {
                    1.0
                } else if exponent == 1.5 {
                    overlap.sqrt().sqrt()
                } else {
                    overlap.powf(0.5 * (exponent - 1.0))
                };
                factor * shape * overlap_rate
            }
            Self::Dashpot { coefficient } => {
                if overlap <= 0.0 {
                    return 0.0;
                }
                coefficient * overlap_rate
            }
        }
    }
}

/// The coefficient ζ̂ = √(2(n+1)) ζ, ζ = −ln e/√(π² + ln² e), that gives the restitution `restitution`
/// ∈ (0, 1] for the exponent `exponent` ∈ [1, 3] (exact; see the module docs).
pub fn damping_for_restitution(exponent: Real, restitution: Real) -> Result<Real, LawError> {
    check_range("restitution e", restitution, 0.0, 1.0, true, "(0, 1]")?;
    check_range("normal exponent n", exponent, 1.0, 3.0, false, "[1, 3]")?;
    let log_e = restitution.ln();
    let zeta = -log_e / (PI * PI + log_e * log_e).sqrt();
    Ok((2.0 * (exponent + 1.0)).sqrt() * zeta)
}

/// The restitution produced by the coefficient ζ̂ ≥ 0 with the exponent n (0 when overdamped, ζ ≥ 1).
pub fn restitution_for_damping(exponent: Real, coefficient: Real) -> Real {
    let zeta = coefficient.max(0.0) / (2.0 * (exponent + 1.0)).sqrt();
    if zeta >= 1.0 {
        0.0
    } else {
        (-PI * zeta / (1.0 - zeta * zeta).sqrt()).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The oracle: integrates x'' = −x^n − ζ̂ x^a x', x(0) = 0, x'(0) = 1 by RK4 until x returns to 0 and
    /// returns −x' there. Steps shrink near x = 0, where x^a is not smooth (the time for x to change by
    /// 0.5 %, between 1e-10 and 2e-3).
    fn integrate_dimensionless_impact(exponent: Real, coefficient: Real) -> Real {
        let a = 0.5 * (exponent - 1.0);
        let acceleration = |x: Real, v: Real| {
            let x = x.max(0.0);
            -x.powf(exponent) - coefficient * x.powf(a) * v
        };
        let (mut x, mut v): (Real, Real) = (0.0, 1.0);
        let mut compressing = true;
        loop {
            let h = (5e-3 * x / v.abs().max(1e-12)).clamp(1e-10, 2e-3);
            let (k1x, k1v) = (v, acceleration(x, v));
            let (k2x, k2v) = (
                v + 0.5 * h * k1v,
                acceleration(x + 0.5 * h * k1x, v + 0.5 * h * k1v),
            );
            let (k3x, k3v) = (
                v + 0.5 * h * k2v,
                acceleration(x + 0.5 * h * k2x, v + 0.5 * h * k2v),
            );
            let (k4x, k4v) = (v + h * k3v, acceleration(x + h * k3x, v + h * k3v));
            let x_new = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            let v_new = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            if compressing && v_new < 0.0 {
                compressing = false;
            }
            if !compressing && x_new <= 0.0 {
                let fraction = x / (x - x_new);
                return -(v + fraction * (v_new - v));
            }
            if !compressing && v_new >= 0.0 {
                return 0.0;
            }
            x = x_new;
            v = v_new;
        }
    }

    #[test]
    fn closed_form_restitution_matches_the_integrated_impact_for_every_exponent() {
        for exponent in [1.0, 1.25, 1.5, 2.0, 3.0] {
            for e in [0.05, 0.3, 0.5, 0.8, 0.95] {
                let coefficient = damping_for_restitution(exponent, e).unwrap();
                let integrated = integrate_dimensionless_impact(exponent, coefficient);
                assert!(
                    (integrated - e).abs() < 1e-9,
                    "n = {exponent}, e = {e}: ζ̂ = {coefficient}, integrated impact gives e = {integrated}, tolerance 1e-9"
                );
                let back = restitution_for_damping(exponent, coefficient);
                assert!(
                    (back - e).abs() < 1e-14,
                    "n = {exponent}: round trip e = {back}, expected {e}"
                );
            }
        }
    }

    #[test]
    fn linear_law_uses_the_damping_ratio_of_the_oscillator() {
        // n = 1: c = ζ̂ √(m k) = 2ζ √(m k), the critical-damping convention.
        let e: Real = 0.4;
        let zeta = -e.ln() / (PI * PI + e.ln().powi(2)).sqrt();
        let coefficient = damping_for_restitution(1.0, e).unwrap();
        assert!(
            (coefficient - 2.0 * zeta).abs() < 1e-15,
            "ζ̂ = {coefficient}, 2ζ = {}",
            2.0 * zeta
        );
        assert_eq!(
            DampingLaw::from_restitution(1.0, e)
                .unwrap()
                .viscous_coefficient(),
            coefficient
        );
        assert_eq!(DampingLaw::None.viscous_coefficient(), 0.0);
        assert_eq!(damping_for_restitution(1.5, 1.0).unwrap(), 0.0);
        assert_eq!(
            restitution_for_damping(1.0, 2.5),
            0.0,
            "overdamped must not rebound"
        );
        assert!(damping_for_restitution(1.5, 0.0).is_err());
        assert!(damping_for_restitution(1.5, 1.2).is_err());
        assert!(damping_for_restitution(0.5, 0.5).is_err());
    }
}
