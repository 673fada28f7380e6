//! Sphere contact laws parameterised from material constants, as YADE and LIGGGHTS do, so that the same
//! scene can be set up in polydem and in both reference codes.
//!
//! Effective quantities of a pair (a wall is a body of infinite radius and mass, taking `None`):
//! - 1/E* = (1 − ν_a²)/E_a + (1 − ν_b²)/E_b;
//! - 1/G* = (2 − ν_a)/G_a + (2 − ν_b)/G_b with G = E/(2(1 + ν));
//! - R* = R_a R_b/(R_a + R_b) (R_a against a wall); m* likewise.
//!
//! Hertz–Mindlin (LIGGGHTS `model hertz tangential history`, YADE `Ip2_FrictMat_FrictMat_MindlinPhys` +
//! `Law2_ScGeom_MindlinPhys_Mindlin`): f_n = (4/3) E* √R* δ^(3/2), tangential stiffness
//! k_t = 8 G* √(R* δ), Coulomb cap μ F_n, damping from e (see [`super::damping`]: exact, and identical to
//! LIGGGHTS' γ_n = 2√(5/6)|β|√(S_n m*)).
//!
//! Linear spring–dashpot (LIGGGHTS `model hooke`): k_n given, or derived from E*, R*, m* and a characteristic
//! speed V as k_n = (16/15) √R* E* (15 m* V²/(16 √R* E*))^(1/5) — the stiffness whose maximum overlap at
//! impact speed V equals the Hertz one; k_t = k_n by default in LIGGGHTS (2/7 k_n with `ktToKnUser on`);
//! damping exact from e.

use super::damping::DampingLaw;
use super::normal::{NormalLaw, RadiusScaling};
use super::tangential::{SpringRotation, TangentialLaw};
use super::{check_range, ContactModel, LawError};
use crate::math::Real;
use std::f64::consts::PI;

/// Elastic constants of a material.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticMaterial {
    /// Young's modulus E (Pa).
    pub young_modulus: Real,
    /// Poisson's ratio ν.
    pub poisson_ratio: Real,
}

impl ElasticMaterial {
    /// The material with Young's modulus `young_modulus` (Pa) and Poisson's ratio `poisson_ratio`.
    ///
    /// Errors: [`LawError::OutOfRange`] unless E > 0 and −1 < ν ≤ 0.5 (both finite).
    pub fn new(young_modulus: Real, poisson_ratio: Real) -> Result<Self, LawError> {
        check_range(
            "Young's modulus E",
            young_modulus,
            0.0,
            Real::MAX,
            true,
            "(0, ∞)",
        )?;
        check_range(
            "Poisson's ratio ν",
            poisson_ratio,
            -1.0,
            0.5,
            true,
            "(−1, 0.5]",
        )?;
        Ok(Self {
            young_modulus,
            poisson_ratio,
        })
    }

    /// Shear modulus G = E/(2(1 + ν)).
    pub fn shear_modulus(&self) -> Real {
        self.young_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

/// E* of a pair.
pub fn effective_young_modulus(a: &ElasticMaterial, b: &ElasticMaterial) -> Real {
    1.0 / ((1.0 - a.poisson_ratio.powi(2)) / a.young_modulus
        + (1.0 - b.poisson_ratio.powi(2)) / b.young_modulus)
}

/// G* of a pair.
pub fn effective_shear_modulus(a: &ElasticMaterial, b: &ElasticMaterial) -> Real {
    1.0 / ((2.0 - a.poisson_ratio) / a.shear_modulus()
        + (2.0 - b.poisson_ratio) / b.shear_modulus())
}

/// x_a x_b/(x_a + x_b), or x_a when b is a wall (`None`): effective radius or mass.
pub fn effective(a: Real, b: Option<Real>) -> Real {
    match b {
        Some(b) => a * b / (a + b),
        None => a,
    }
}

/// A pair of spheres (or a sphere and a wall) with the contact parameters the reference codes take.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpherePair {
    /// Elastic constants of A.
    pub material_a: ElasticMaterial,
    /// Elastic constants of B (of the wall when `radius_b` is `None`).
    pub material_b: ElasticMaterial,
    /// Radius of A (m).
    pub radius_a: Real,
    /// Radius of B (m); `None` for a wall.
    pub radius_b: Option<Real>,
    /// Coefficient of restitution e ∈ (0, 1].
    pub restitution: Real,
    /// Friction coefficient μ ≥ 0.
    pub friction: Real,
}

/// The Hertz–Mindlin model of a sphere pair.
pub fn hertz_mindlin(pair: &SpherePair) -> Result<ContactModel, LawError> {
    check_range("radius", pair.radius_a, 0.0, Real::MAX, true, "(0, ∞)")?;
    if let Some(r) = pair.radius_b {
        check_range("radius", r, 0.0, Real::MAX, true, "(0, ∞)")?;
    }
    check_range("friction μ", pair.friction, 0.0, Real::MAX, false, "[0, ∞)")?;
    let radius = effective(pair.radius_a, pair.radius_b);
    let young = effective_young_modulus(&pair.material_a, &pair.material_b);
    let shear = effective_shear_modulus(&pair.material_a, &pair.material_b);
    let damping = DampingLaw::from_restitution(1.5, pair.restitution)?;
    Ok(ContactModel {
        normal: NormalLaw::hertz(4.0 / 3.0 * young * radius.sqrt())?,
        damping,
        tangential: TangentialLaw::Mindlin {
            coefficient: 8.0 * shear * radius.sqrt(),
            friction: pair.friction,
            rotation: SpringRotation::Exact,
        },
    })
}

/// The linear spring–dashpot with exact restitution: f_n = k_n δ + c δ̇, c = 2ζ√(m* k_n),
/// ζ = −ln e/√(π² + ln² e); tangential spring k_t with Coulomb cap μ.
pub fn linear_spring_dashpot(
    normal_stiffness: Real,
    tangential_stiffness: Real,
    restitution: Real,
    friction: Real,
) -> Result<ContactModel, LawError> {
    Ok(ContactModel {
        normal: NormalLaw::linear(normal_stiffness)?,
        damping: DampingLaw::from_restitution(1.0, restitution)?,
        tangential: TangentialLaw::spring(tangential_stiffness, friction)?,
    })
}

/// Options of the Hertz–Mindlin law that differ between the reference codes' settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzMindlinOptions {
    /// Tangential dashpot c_t = 2√(5/6) β √(m* k_t) while sticking (LIGGGHTS `tangential_damping`, on by
    /// default there; YADE's `betas`).
    pub tangential_damping: bool,
    /// Total normal force never attractive (LIGGGHTS `limitForce on`; off by default there).
    pub limit_force: bool,
}

/// Hertz–Mindlin of a material pair from E, ν of each material, the pair's restitution e and friction μ,
/// per √m of R* (scaled by each contact's √R*, see [`crate::law::pair`]): k_n = (4/3) E*, k_t coefficient
/// 8 G*, normal damping √5 ζ (= LIGGGHTS' 2√(5/6) β √(S_n m*) with S_n = 2E*√(R*δ)), tangential damping
/// 2√(5/6) ζ on √(m* k_t) when enabled, ζ = −ln e/√(π² + ln² e).
pub fn material_hertz_mindlin(
    a: &ElasticMaterial,
    b: &ElasticMaterial,
    restitution: Real,
    friction: Real,
    options: HertzMindlinOptions,
) -> Result<ContactModel, LawError> {
    check_range("friction μ", friction, 0.0, Real::MAX, false, "[0, ∞)")?;
    let young = effective_young_modulus(a, b);
    let shear = effective_shear_modulus(a, b);
    let damping = DampingLaw::from_restitution(1.5, restitution)?;
    let mut normal = NormalLaw::hertz(4.0 / 3.0 * young)?;
    normal.radius_scaling = RadiusScaling::SqrtEffectiveRadius;
    if options.limit_force {
        normal = normal.with_force_limit();
    }
    let coefficient = 8.0 * shear;
    let tangential = if friction == 0.0 {
        TangentialLaw::None
    } else if options.tangential_damping {
        let log_e = restitution.ln();
        let zeta = -log_e / (PI * PI + log_e * log_e).sqrt();
        TangentialLaw::DampedMindlin {
            coefficient,
            friction,
            damping: 2.0 * (5.0_f64 / 6.0).sqrt() * zeta,
            rotation: SpringRotation::Exact,
        }
    } else {
        TangentialLaw::Mindlin {
            coefficient,
            friction,
            rotation: SpringRotation::Exact,
        }
    };
    Ok(ContactModel {
        normal,
        damping,
        tangential,
    })
}

/// The linear spring–dashpot with a constant dashpot c_n (N s/m) instead of a restitution, as LIGGGHTS'
/// `hooke/stiffness absolute_damping on tangential_damping off` (`gamman_abs`) and YADE's `ViscElMat`:
/// f_n = k_n δ + c_n δ̇; tangential spring k_t with Coulomb cap μ; `limit_force` clamps f_n at zero.
pub fn linear_dashpot(
    normal_stiffness: Real,
    tangential_stiffness: Real,
    normal_damping: Real,
    friction: Real,
    limit_force: bool,
) -> Result<ContactModel, LawError> {
    let mut normal = NormalLaw::linear(normal_stiffness)?;
    if limit_force {
        normal = normal.with_force_limit();
    }
    let tangential = if friction == 0.0 {
        TangentialLaw::None
    } else {
        TangentialLaw::spring(tangential_stiffness, friction)?
    };
    Ok(ContactModel {
        normal,
        damping: DampingLaw::dashpot(normal_damping)?,
        tangential,
    })
}

/// LIGGGHTS `hooke` normal stiffness from E*, R*, m* and the characteristic speed V (m/s):
/// k_n = (16/15) √R* E* (15 m* V²/(16 √R* E*))^(1/5).
pub fn liggghts_hooke_stiffness(
    effective_young_modulus: Real,
    effective_radius: Real,
    effective_mass: Real,
    characteristic_speed: Real,
) -> Real {
    let root = effective_radius.sqrt();
    16.0 / 15.0
        * root
        * effective_young_modulus
        * (15.0 * effective_mass * characteristic_speed.powi(2)
            / (16.0 * root * effective_young_modulus))
            .powf(0.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hooke_stiffness_gives_the_hertz_maximum_overlap_at_the_characteristic_speed() {
        let (e_star, r_star, m_star, v): (Real, Real, Real, Real) = (3.5e9, 0.005, 2e-3, 1.3);
        let k = liggghts_hooke_stiffness(e_star, r_star, m_star, v);
        let linear_max = v * (m_star / k).sqrt();
        // Hertz (Johnson 1985, eq. 11.24): δ_max = (15 m* v²/(16 E* √R*))^(2/5).
        let hertz_max = (15.0 * m_star * v * v / (16.0 * e_star * r_star.sqrt())).powf(0.4);
        assert!(
            (linear_max - hertz_max).abs() < 1e-13 * hertz_max,
            "linear δ_max {linear_max}, Hertz δ_max {hertz_max}"
        );
    }

    #[test]
    fn hertz_mindlin_constants_follow_the_material_pair() {
        let steel = ElasticMaterial::new(2.0e11, 0.3).unwrap();
        let pair = SpherePair {
            material_a: steel,
            material_b: steel,
            radius_a: 0.01,
            radius_b: Some(0.01),
            restitution: 0.8,
            friction: 0.4,
        };
        let model = hertz_mindlin(&pair).unwrap();
        // Identical materials: E* = E/(2(1 − ν²)), G* = G/(2(2 − ν)), R* = R/2.
        let e_star = 2.0e11 / (2.0 * (1.0 - 0.09));
        let g_star = steel.shear_modulus() / (2.0 * (2.0 - 0.3));
        let k_n = 4.0 / 3.0 * e_star * (0.005 as Real).sqrt();
        assert!(
            (model.normal.stiffness - k_n).abs() < 1e-12 * k_n,
            "k_n {}",
            model.normal.stiffness
        );
        assert_eq!(model.normal.exponent, 1.5);
        let TangentialLaw::Mindlin {
            coefficient,
            friction,
            ..
        } = model.tangential
        else {
            panic!(
                "expected the Mindlin tangential law, got {:?}",
                model.tangential
            );
        };
        let k_t = 8.0 * g_star * (0.005 as Real).sqrt();
        assert!(
            (coefficient - k_t).abs() < 1e-12 * k_t,
            "k_t coefficient {coefficient}, expected {k_t}"
        );
        assert_eq!(friction, 0.4);
        let wall = SpherePair {
            radius_b: None,
            ..pair
        };
        let against_wall = hertz_mindlin(&wall).unwrap();
        let ratio = against_wall.normal.stiffness / model.normal.stiffness;
        assert!(
            (ratio - (2.0 as Real).sqrt()).abs() < 1e-12,
            "wall/sphere stiffness ratio {ratio}"
        );
    }
}
