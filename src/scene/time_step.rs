//! The time step: derived from the shortest contact time of the scene, or given and checked against the
//! stability limit.
//!
//! For every material pair whose bodies can meet (two dynamic bodies, or a dynamic body and a wall or a
//! non-dynamic body), the effective mass m* is formed from the lightest dynamic body of each material
//! (m_a m_b/(m_a + m_b), or m_a against a wall) — the lightest bodies have the shortest contacts.
//!
//! - Contact time of a head-on elastic impact: t_c = π √(m*/k_n) for the linear law; for the power law
//!   f = k_n δ^n at the characteristic speed V, t_c = [`crate::law::NormalLaw::elastic_contact_time`].
//!   The derived step is Δt = min t_c / N with N = `steps_per_contact` (the energy gates use N = 200; DEM
//!   practice is 20–50 for dissipative runs).
//! - Stability: velocity Verlet on an oscillator of angular frequency ω is stable for ω Δt < 2. The stiffest
//!   mode of a contact is bounded by ω² = κ k_eff / m*, with k_eff the larger of the normal tangent stiffness
//!   at the largest overlap of an impact at V (n k_n δ_max^(n−1); k_n for the linear law) and the tangential
//!   stiffness k_t (the laws state both: [`crate::law::NormalLaw::impact_time_and_stiffness`],
//!   [`crate::law::TangentialLaw::stability_stiffness`]), and κ = max over dynamic bodies of (1 + m r_b²/J_min) (r_b the bounding radius, J_min
//!   the smallest principal moment): a force at a lever arm r_b also turns the body, which lowers the
//!   effective mass of the contact point by up to that factor (2.5 + 1 for a solid sphere). The limit is
//!   Δt_max = 2/ω for the linear law and the tangential spring; a given step above it is refused with an
//!   error stating the limit, and a derived one above it (N too small) as well.
//! - Overshoot of a stiffening law (n > 1). The tangent stiffness n k_n δ^(n−1) grows with the overlap, and
//!   the discrete orbit overshoots the exact peak overlap: velocity Verlet on x'' = −ω²x conserves exactly
//!   v² + ω²(1 − r²) x², r = ωΔt/2, so an approach at speed v₀ turns at x = v₀/(ω √(1 − r²)), 1/√(1 − r²)
//!   beyond the exact peak v₀/ω. Freezing the stiffness at the discrete peak (the stiffest point of the
//!   orbit), the overlap reached is δ_d = δ_max/√(1 − r_d²) and the stiffness there ω_d = ω (δ_d/δ_max)^((n−1)/2),
//!   so r_d = ω_d Δt/2 solves r_d (1 − r_d²)^p = r with p = (n − 1)/4 and r = ωΔt/2 at the exact peak δ_max.
//!   A bounded orbit (r_d < 1) exists only while r ≤ max over r_d of r_d (1 − r_d²)^p, reached at
//!   r_d² = 1/(1 + 2p):
//!
//!   ```text
//!   Δt_max = (2/ω) · f(n),   f(n) = (1 + 2p)^(−1/2) (2p/(1 + 2p))^p,   p = (n − 1)/4
//!   ```
//!
//!   f(1) = 1 (the linear law has no overshoot feedback) and f(3/2) = 0.7314. Without this factor the
//!   `stress_time_step` case found the largest stable Hertz-type step at 0.81–0.87 of 2/ω (linear law: 1.34–1.89):
//!   near 2/ω the rocking body's overlaps reached 5–14 times the overlap of the fall the guard assumed, which
//!   for a stiffening law raises ω past the limit. The frozen-stiffness argument is a bound of the mechanism,
//!   not a proof for every orbit; the case measures the margin.
//! - Not covered: the smoothed wall depth (`crate::contact::wall_depth`) adds a rocking stiffness of order
//!   k_n δ^n / h at lever arms up to r_b; it stays within the bound above while the band h is at least the
//!   overlap (its documented rule). A band far below the overlaps of a scene needs a smaller step.

use crate::law::pair::contact_radius;
use crate::law::ContactModel;
use crate::math::Real;
use crate::shape::Shape;
use crate::world::MaterialTable;

/// How the time step was chosen.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimeStepInfo {
    /// The time step used (s).
    pub dt: Real,
    /// Whether it was derived (true) or given (false).
    pub derived: bool,
    /// The shortest contact time of the scene, t_c,min (s).
    pub contact_time: Real,
    /// The stability limit Δt_max = 2/ω_max (s).
    pub stability_limit: Real,
}

/// One pair that can meet: its law and effective mass.
#[derive(Clone, Copy, Debug)]
pub struct PairEstimate {
    /// The contact law of the pair.
    pub model: ContactModel,
    /// Effective mass m* = m_a m_b/(m_a + m_b) of the pair (kg).
    pub effective_mass: Real,
}

/// Why no contact time could be computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStepIssue {
    /// A nonlinear law needs the characteristic speed.
    NeedsSpeed,
    /// No pair of the scene can meet.
    NoContacts,
}

/// (t_c,min, Δt_max) over the pairs, with the rotational factor `kappa` and the speed `speed` (m/s).
pub fn contact_time_and_limit(
    pairs: &[PairEstimate],
    kappa: Real,
    speed: Option<Real>,
) -> Result<(Real, Real), TimeStepIssue> {
    if pairs.is_empty() {
        return Err(TimeStepIssue::NoContacts);
    }
    let (mut t_c, mut limit) = (Real::INFINITY, Real::INFINITY);
    for p in pairs {
        let law = p.model.normal;
        let m = p.effective_mass;
        let (tc, k_normal) = law
            .impact_time_and_stiffness(m, speed)
            .ok_or(TimeStepIssue::NeedsSpeed)?;
        let k_tangential = p.model.tangential.stability_stiffness();
        let omega_normal = (kappa * k_normal / m).sqrt();
        let omega_tangential = (kappa * k_tangential / m).sqrt();
        t_c = t_c.min(tc);
        limit = limit
            .min(2.0 / omega_normal * overshoot_factor(law.exponent))
            .min(2.0 / omega_tangential);
    }
    Ok((t_c, limit))
}

/// What the estimate reads of one body.
#[derive(Clone, Copy, Debug)]
pub struct BodyFacts<'a> {
    /// Material id.
    pub material: u32,
    /// Whether the body moves under forces (walls and fixed bodies are the heavy side of a pair).
    pub dynamic: bool,
    /// Mass (kg).
    pub mass: Real,
    /// Smallest principal moment of inertia (kg·m²).
    pub smallest_moment: Real,
    /// Bounding radius r_b (m).
    pub bounding_radius: Real,
    /// The shape, for its contact radius (asked only of the lightest body of each material).
    pub shape: &'a Shape,
}

/// The pairs that can meet, with the rotational factor κ: per material the lightest dynamic body's
/// mass and contact radius, and whether a wall (`wall_materials`) or a non-dynamic body of it exists;
/// then the law and effective mass of every way two materials' bodies can meet (module docs). Shared
/// by the scene's guard at load and the step's check during the run.
pub fn pair_estimates<'a>(
    table: &MaterialTable,
    bodies: impl IntoIterator<Item = BodyFacts<'a>>,
    wall_materials: impl IntoIterator<Item = u32>,
) -> (Vec<PairEstimate>, Real) {
    let lightest = Lightest::of(table.len(), bodies, wall_materials);
    (estimates_of(table, &lightest), lightest.kappa)
}

/// The largest approach speed (m/s) at which the step `dt` stays within the stability limit of
/// [`contact_time_and_limit`] (the speed-dependent laws' limit falls as the impact speed grows; a
/// speed-independent limit is met or not at any speed): ∞ when no speed reaches it, 0 when even a
/// vanishing speed does. Found by bisection in log space (the limit is non-increasing in the speed).
pub fn critical_speed(pairs: &[PairEstimate], kappa: Real, dt: Real) -> Real {
    let limit = |v: Real| match contact_time_and_limit(pairs, kappa, Some(v)) {
        Ok((_, limit)) => limit,
        Err(_) => Real::INFINITY,
    };
    let (mut lo, mut hi): (Real, Real) = (1e-12, 1e12);
    if limit(hi) >= dt {
        return Real::INFINITY;
    }
    if limit(lo) < dt {
        return 0.0;
    }
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if limit(mid) >= dt {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi <= lo * (1.0 + 1e-12) {
            break;
        }
    }
    lo
}

/// The stability limit Δt_max (s) of [`contact_time_and_limit`] at the approach speed `speed` (m/s).
pub fn limit_at(pairs: &[PairEstimate], kappa: Real, speed: Real) -> Real {
    contact_time_and_limit(pairs, kappa, Some(speed)).map_or(Real::INFINITY, |(_, limit)| limit)
}

/// Per material: the lightest dynamic body's mass and contact radius, and whether a wall or a non-dynamic
/// body of it exists; the rotational factor κ over all dynamic bodies.
struct Lightest {
    mass: Vec<Real>,
    /// Contact radius of the lightest body of each material (for laws that scale with R*).
    radius: Vec<Real>,
    has_obstacle: Vec<bool>,
    /// κ = max (1 + m r_b²/J_min) of the module docs.
    kappa: Real,
}

impl Lightest {
    fn of<'a>(
        n_mat: usize,
        bodies: impl IntoIterator<Item = BodyFacts<'a>>,
        wall_materials: impl IntoIterator<Item = u32>,
    ) -> Self {
        let mut l = Lightest {
            mass: vec![Real::INFINITY; n_mat],
            radius: vec![Real::INFINITY; n_mat],
            has_obstacle: vec![false; n_mat],
            kappa: 1.0,
        };
        for b in bodies {
            let mat = b.material as usize;
            if b.dynamic {
                if b.mass < l.mass[mat] {
                    l.mass[mat] = b.mass;
                    l.radius[mat] = contact_radius(b.shape).unwrap_or(Real::INFINITY);
                }
                let r = b.bounding_radius;
                l.kappa = l.kappa.max(1.0 + b.mass * r * r / b.smallest_moment);
            } else {
                l.has_obstacle[mat] = true;
            }
        }
        for m in wall_materials {
            l.has_obstacle[m as usize] = true;
        }
        l
    }
}

/// The law and effective mass of every way two materials' bodies can meet.
fn estimates_of(table: &MaterialTable, l: &Lightest) -> Vec<PairEstimate> {
    let n_mat = table.len();
    let mut estimates = Vec::new();
    for a in 0..n_mat {
        for b in a..n_mat {
            let Some(model) = table.model(a as u32, b as u32) else {
                continue;
            };
            let (ma, mb) = (l.mass[a], l.mass[b]);
            let (ra, rb) = (l.radius[a], l.radius[b]);
            // (m*, R*) of each way the pair can meet; a wall or fixed body counts as flat (R* = R, the
            // stiffest Hertz contact of that body).
            let mut candidates = Vec::new();
            if ma.is_finite() && mb.is_finite() {
                candidates.push((ma * mb / (ma + mb), ra * rb / (ra + rb)));
            }
            if ma.is_finite() && l.has_obstacle[b] {
                candidates.push((ma, ra));
            }
            if mb.is_finite() && l.has_obstacle[a] {
                candidates.push((mb, rb));
            }
            for (m, r) in candidates {
                estimates.push(PairEstimate {
                    model: model.for_root_radius(r.sqrt()),
                    effective_mass: m,
                });
            }
        }
    }
    estimates
}

/// f(n) of the module docs: the fraction of 2/ω at which a stiffening power law f = k δ^n (n ≥ 1) stays
/// stable when the discrete orbit overshoots the exact peak overlap (1 for the linear law).
pub fn overshoot_factor(exponent: Real) -> Real {
    let p = (exponent - 1.0) / 4.0;
    if p <= 0.0 {
        return 1.0;
    }
    (1.0 + 2.0 * p).powf(-0.5) * (2.0 * p / (1.0 + 2.0 * p)).powf(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::{DampingLaw, NormalLaw, TangentialLaw};
    use std::f64::consts::PI;

    #[test]
    fn linear_contact_time_and_limit_follow_the_oscillator() {
        let model = ContactModel {
            normal: NormalLaw::linear(1e6).unwrap(),
            damping: DampingLaw::None,
            tangential: TangentialLaw::None,
        };
        let pairs = [PairEstimate {
            model,
            effective_mass: 2.0,
        }];
        let (tc, limit) = contact_time_and_limit(&pairs, 1.0, None).unwrap();
        let expected_tc = PI * (2.0f64 / 1e6).sqrt();
        assert!(
            (tc - expected_tc).abs() < 1e-15 * expected_tc,
            "t_c {tc}, expected {expected_tc}"
        );
        // 2/ω = 2√(m/k) = (2/π) t_c.
        assert!(
            (limit - 2.0 / PI * expected_tc).abs() < 1e-15 * expected_tc,
            "limit {limit}"
        );
    }

    #[test]
    fn nonlinear_law_without_speed_is_an_issue() {
        let model = ContactModel {
            normal: NormalLaw::hertz(1e8).unwrap(),
            damping: DampingLaw::None,
            tangential: TangentialLaw::None,
        };
        let pairs = [PairEstimate {
            model,
            effective_mass: 1.0,
        }];
        assert_eq!(
            contact_time_and_limit(&pairs, 1.0, None),
            Err(TimeStepIssue::NeedsSpeed)
        );
    }

    /// f(n) is the maximum over r_d ∈ (0, 1) of r_d (1 − r_d²)^((n−1)/4), checked by a fine scan; 1 for the
    /// linear law, and the Hertz-type limit is f(3/2) times 2/ω at the impact's peak overlap.
    #[test]
    fn overshoot_factor_is_the_largest_stable_ratio_of_the_frozen_stiffness_orbit() {
        assert_eq!(overshoot_factor(1.0), 1.0);
        for n in [1.25, 1.5, 2.0, 3.0] {
            let p = (n - 1.0) / 4.0;
            let scan = (1..200_000)
                .map(|i| {
                    let r = i as Real / 200_000.0;
                    r * (1.0 - r * r).powf(p)
                })
                .fold(0.0, Real::max);
            let f = overshoot_factor(n);
            assert!(
                (f - scan).abs() < 1e-8 && f < 1.0,
                "n = {n}: f = {f}, scan maximum {scan}"
            );
        }
        let model = ContactModel {
            normal: NormalLaw::hertz(1e8).unwrap(),
            damping: DampingLaw::None,
            tangential: TangentialLaw::None,
        };
        let (m, v) = (2.0, 3.0);
        let pairs = [PairEstimate {
            model,
            effective_mass: m,
        }];
        let (_, limit) = contact_time_and_limit(&pairs, 1.0, Some(v)).unwrap();
        let delta = (2.5 * m * v * v / (2.0 * 1e8)).powf(1.0 / 2.5);
        let omega = (1.5 * 1e8 * delta.sqrt() / m).sqrt();
        let want = 2.0 / omega * overshoot_factor(1.5);
        assert!(
            (limit - want).abs() < 1e-12 * want,
            "limit {limit}, expected {want}"
        );
    }
}
