//! The normal power law of paper eqs. 4–5: F_n = k_n δ_M^n along n_M, applied at c_M.
//!
//! With the Minkowski overlap δ_M, normal n_M and point c_M this force derives from the potential
//! U(δ) = k_n δ^(n+1)/(n+1), which is what makes an elastic impact conserve energy (paper section 2.3 and its
//! reference 14); [`power_law_potential`] reports it for the energy ledger.

use super::{check_range, LawError};
use crate::math::Real;

/// δ^n, with the linear and Hertz exponents by multiplication and square root (`powf` costs several times
/// more, and these two are the laws of every sphere benchmark).
#[inline]
fn power(overlap: Real, exponent: Real) -> Real {
    if exponent == 1.0 {
        overlap
    } else if exponent == 1.5 {
        overlap * overlap.sqrt()
    } else {
        overlap.powf(exponent)
    }
}

/// f_n = k_n δ^n (N) for an overlap δ ≥ 0 (m); zero for δ ≤ 0.
#[inline]
pub fn power_law_force(stiffness: Real, exponent: Real, overlap: Real) -> Real {
    if overlap <= 0.0 {
        0.0
    } else {
        stiffness * power(overlap, exponent)
    }
}

/// U = k_n δ^(n+1)/(n+1) (J), the elastic potential of [`power_law_force`]; zero for δ ≤ 0.
#[inline]
pub fn power_law_potential(stiffness: Real, exponent: Real, overlap: Real) -> Real {
    if overlap <= 0.0 {
        0.0
    } else {
        stiffness * overlap * power(overlap, exponent) / (exponent + 1.0)
    }
}

/// The tangent stiffness df_n/dδ = n k_n δ^(n−1) (N/m), used for stable time steps.
pub fn power_law_tangent_stiffness(stiffness: Real, exponent: Real, overlap: Real) -> Real {
    if overlap <= 0.0 {
        if exponent == 1.0 {
            stiffness
        } else {
            0.0
        }
    } else {
        exponent * stiffness * overlap.powf(exponent - 1.0)
    }
}

/// How the stiffnesses of a contact model follow the two bodies in contact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RadiusScaling {
    /// The stiffnesses are constants of the material pair.
    #[default]
    Constant,
    /// The stiffnesses are given per √m and multiplied by √R* of each contact (R* = R_A R_B/(R_A + R_B),
    /// R against a wall): Hertz–Mindlin from material constants, k_n = (4/3) E* √R* and
    /// k_t = 8 G* √(R* δ). See [`crate::law::pair`].
    SqrtEffectiveRadius,
}

/// The normal slot: f_n = k_n δ^n.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalLaw {
    /// k_n, in N/m^n (per √m when `radius_scaling` is [`RadiusScaling::SqrtEffectiveRadius`]).
    pub stiffness: Real,
    /// n ≥ 1 (1 linear, 1.5 Hertz-type).
    pub exponent: Real,
    /// Whether k_n (and the tangential stiffness of the same model) follow R* of each contact; default
    /// constant (the paper's laws).
    #[serde(default)]
    pub radius_scaling: RadiusScaling,
    /// When true the total normal force (elastic + damping) is clamped at zero, never attractive — LIGGGHTS'
    /// `limitForce on`, and what YADE's Hertz–Mindlin does. Default false: the contact then ends at δ = 0
    /// and the restitution of [`crate::law::damping`] is exact; with the clamp the contact ends earlier, when
    /// the force reaches zero, and the rebound is faster (e = 0.5 input gives 0.550 with the Hertz law).
    #[serde(default)]
    pub never_attractive: bool,
}

impl NormalLaw {
    /// Validated constructor: k_n > 0 and 1 ≤ n ≤ 3.
    pub fn new(stiffness: Real, exponent: Real) -> Result<Self, LawError> {
        check_range(
            "normal stiffness k_n",
            stiffness,
            0.0,
            Real::MAX,
            true,
            "(0, ∞)",
        )?;
        check_range("normal exponent n", exponent, 1.0, 3.0, false, "[1, 3]")?;
        Ok(Self {
            stiffness,
            exponent,
            radius_scaling: RadiusScaling::Constant,
            never_attractive: false,
        })
    }

    /// The same law with the total normal force clamped at zero (see [`NormalLaw::never_attractive`]).
    pub fn with_force_limit(self) -> Self {
        Self {
            never_attractive: true,
            ..self
        }
    }

    /// The linear law f_n = k_n δ.
    pub fn linear(stiffness: Real) -> Result<Self, LawError> {
        Self::new(stiffness, 1.0)
    }

    /// The Hertz-type law f_n = k_n δ^(3/2).
    pub fn hertz(stiffness: Real) -> Result<Self, LawError> {
        Self::new(stiffness, 1.5)
    }

    /// The elastic normal force f_n(δ) = k_n δⁿ (N) at overlap δ (m); zero for δ ≤ 0.
    pub fn force(&self, overlap: Real) -> Real {
        power_law_force(self.stiffness, self.exponent, overlap)
    }

    /// The elastic energy k_n δⁿ⁺¹/(n + 1) (J) stored at overlap δ (m); zero for δ ≤ 0.
    pub fn potential(&self, overlap: Real) -> Real {
        power_law_potential(self.stiffness, self.exponent, overlap)
    }

    /// Whether the stiffnesses of a model with this normal slot follow R* of each contact
    /// ([`RadiusScaling::SqrtEffectiveRadius`]).
    #[inline]
    pub fn scales_with_radius(&self) -> bool {
        match self.radius_scaling {
            RadiusScaling::Constant => false,
            RadiusScaling::SqrtEffectiveRadius => true,
        }
    }

    /// Whether the law's contact time and stiffest point depend on the impact speed (n ≠ 1), so that the
    /// time-step guard needs a characteristic speed.
    pub fn needs_impact_speed(&self) -> bool {
        self.exponent != 1.0
    }

    /// What the time-step guard needs of the normal law for a head-on elastic impact of effective mass
    /// `mass` (kg) at speed `speed` (m/s): the contact time (s) and the stiffness (N/m) of the stiffest
    /// point. Linear law: π√(m/k_n) and k_n, whatever the speed. Power law: [`Self::elastic_contact_time`]
    /// and the tangent stiffness n k_n δ_max^(n−1) at the peak overlap δ_max = ((n+1) m v²/(2k_n))^(1/(n+1));
    /// `None` without a speed.
    pub fn impact_time_and_stiffness(
        &self,
        mass: Real,
        speed: Option<Real>,
    ) -> Option<(Real, Real)> {
        if !self.needs_impact_speed() {
            return Some((
                std::f64::consts::PI * (mass / self.stiffness).sqrt(),
                self.stiffness,
            ));
        }
        let v = speed?;
        let n = self.exponent;
        let max_overlap = ((n + 1.0) * mass * v * v / (2.0 * self.stiffness)).powf(1.0 / (n + 1.0));
        Some((
            self.elastic_contact_time(mass, v),
            n * self.stiffness * max_overlap.powf(n - 1.0),
        ))
    }

    /// Duration of an elastic (undamped) impact at approach speed `speed` with effective mass `mass`:
    /// t_c = 2 (δ_max/v) ∫₀¹ dx/√(1 − x^(n+1)), δ_max = ((n+1) m v²/(2k))^(1/(n+1)). For n = 1 this is π√(m/k).
    pub fn elastic_contact_time(&self, mass: Real, speed: Real) -> Real {
        let n = self.exponent;
        let max_overlap =
            ((n + 1.0) * mass * speed * speed / (2.0 * self.stiffness)).powf(1.0 / (n + 1.0));
        // ∫₀¹ (1 − x^p)^(−1/2) dx = Γ(1 + 1/p) Γ(1/2) / Γ(1/2 + 1/p), p = n + 1, by the substitution
        // x = s^(1/p) (a Beta integral); Γ by the Lanczos-free Stirling series below.
        let p = n + 1.0;
        let integral = (ln_gamma(1.0 + 1.0 / p) + ln_gamma(0.5) - ln_gamma(0.5 + 1.0 / p)).exp();
        2.0 * max_overlap / speed * integral
    }
}

/// ln Γ(x) for x > 0: shift x above 10 with Γ(x+1) = xΓ(x), then Stirling's series to x⁻⁹
/// (A&S 6.1.41), relative error < 1e-15 there.
fn ln_gamma(mut x: Real) -> Real {
    let mut shift = 0.0;
    while x < 10.0 {
        shift -= x.ln();
        x += 1.0;
    }
    let inv = 1.0 / x;
    let inv2 = inv * inv;
    let series = inv
        * (1.0 / 12.0
            - inv2 * (1.0 / 360.0 - inv2 * (1.0 / 1260.0 - inv2 * (1.0 / 1680.0 - inv2 / 1188.0))));
    shift + (x - 0.5) * x.ln() - x + 0.5 * (2.0 * std::f64::consts::PI).ln() + series
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn potential_is_the_integral_of_the_force() {
        for exponent in [1.0, 1.5, 2.0] {
            let (k, delta) = (3.0e6, 2.0e-4);
            // Composite Simpson on [0, δ] (exact enough: the integrand is smooth away from 0, and for n = 1.5
            // the δ^1.5 start costs ~h^2.5).
            let panels = 20_000;
            let h = delta / panels as Real;
            let mut sum = power_law_force(k, exponent, 0.0) + power_law_force(k, exponent, delta);
            for i in 1..panels {
                let w = if i % 2 == 1 { 4.0 } else { 2.0 };
                sum += w * power_law_force(k, exponent, i as Real * h);
            }
            let integral = sum * h / 3.0;
            let potential = power_law_potential(k, exponent, delta);
            assert!(
                (integral - potential).abs() <= 1e-9 * potential,
                "n = {exponent}: ∫f dδ = {integral}, potential {potential}, tolerance 1e-9 relative"
            );
        }
        assert_eq!(power_law_force(1.0, 1.5, -1e-3), 0.0);
        assert_eq!(power_law_potential(1.0, 1.5, -1e-3), 0.0);
    }

    #[test]
    fn linear_contact_time_is_pi_sqrt_m_over_k() {
        let law = NormalLaw::linear(2e7).unwrap();
        let (m, v) = (0.7, 3.0);
        let expected = std::f64::consts::PI * (m / 2e7 as Real).sqrt();
        let measured = law.elastic_contact_time(m, v);
        assert!(
            (measured - expected).abs() <= 1e-13 * expected,
            "t_c = {measured}, π√(m/k) = {expected}"
        );
    }

    #[test]
    fn hertz_contact_time_matches_the_closed_form() {
        // Hertz: t_c = 2.868... (m²/(k² v))^(1/5) with the constant 2 (5/4)^(2/5) √π Γ(7/5)/Γ(9/10); here the
        // Beta integral is checked against direct quadrature of ∫₀¹ (1 − x^2.5)^(−1/2) dx instead, by the
        // substitution x = 1 − s² that removes the end-point singularity.
        let law = NormalLaw::hertz(1e9).unwrap();
        let (m, v) = (0.01, 2.0);
        let max_overlap = (2.5 * m * v * v / (2.0 * 1e9 as Real)).powf(0.4);
        let panels = 200_000;
        let h = 1.0 / panels as Real;
        let mut integral = 0.0;
        for i in 0..panels {
            let s = (i as Real + 0.5) * h;
            let x: Real = 1.0 - s * s;
            // dx = −2s ds; (1 − x^2.5)^(−1/2) · 2s
            integral += h * 2.0 * s / (1.0 - x.powf(2.5)).sqrt();
        }
        let expected = 2.0 * max_overlap / v * integral;
        let measured = law.elastic_contact_time(m, v);
        assert!(
            (measured - expected).abs() <= 1e-8 * expected,
            "Hertz t_c = {measured}, quadrature {expected}"
        );
    }

    /// The guard's facts: π√(m/k) and k for the linear law at any speed; for a power law, the elastic
    /// contact time and the tangent stiffness n k δ^(n−1) at the peak overlap of the energy balance
    /// m v²/2 = k δ^(n+1)/(n+1), and nothing without a speed.
    #[test]
    fn impact_time_and_stiffness_are_the_guard_quantities() {
        let (m, v) = (0.3, 2.0);
        let linear = NormalLaw::linear(4e6).unwrap();
        let (tc, k) = linear.impact_time_and_stiffness(m, None).unwrap();
        let expected = std::f64::consts::PI * (m / 4e6 as Real).sqrt();
        assert!(
            (tc - expected).abs() <= 1e-15 * expected && k == 4e6,
            "linear: t_c {tc} (expected {expected}), k {k} (expected 4e6)"
        );
        assert!(!linear.needs_impact_speed());
        let hertz = NormalLaw::hertz(1e9).unwrap();
        assert!(hertz.needs_impact_speed());
        assert_eq!(hertz.impact_time_and_stiffness(m, None), None);
        let (tc, k) = hertz.impact_time_and_stiffness(m, Some(v)).unwrap();
        let peak = (2.5 * 0.5 * m * v * v / 1e9 as Real).powf(1.0 / 2.5);
        let k_expected = power_law_tangent_stiffness(1e9, 1.5, peak);
        let t_expected = hertz.elastic_contact_time(m, v);
        assert!(
            (k - k_expected).abs() <= 1e-12 * k_expected && tc == t_expected,
            "Hertz: k {k} (expected {k_expected}, tolerance 1e-12 relative), t_c {tc} (expected {t_expected})"
        );
    }

    #[test]
    fn invalid_parameters_are_refused() {
        assert!(NormalLaw::new(-1.0, 1.0).is_err());
        assert!(NormalLaw::new(1.0, 0.5).is_err());
        assert!(NormalLaw::new(Real::NAN, 1.5).is_err());
    }
}
