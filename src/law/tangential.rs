//! Tangential law: an incremental spring with a Coulomb cap (the paper's "classic Coulomb friction law").
//!
//! Per contact the caller stores a [`TangentialHistory`]: the accumulated tangential displacement u (m, of
//! B relative to A, world frame, in the tangent plane) and the normal it was last expressed in. Each
//! evaluation:
//! 1. carries u into the current tangent plane: by default ([`SpringRotation::Exact`]) by the smallest
//!    rotation taking the stored normal to the current one (Rodrigues), then removes any remaining normal
//!    component (round-off) keeping |u|; as an option ([`SpringRotation::Projection`], LIGGGHTS' rule)
//!    by removing its component along the current normal only;
//! 2. adds the tangential relative displacement of this step, u ← u + v_t Δt;
//! 3. forms the trial force F_t = −k_t u (on B);
//! 4. caps it: if |F_t| > μ F_n (F_n the compressive normal force, ≥ 0), F_t ← μ F_n F_t/|F_t| and
//!    u ← −F_t / k_t (sliding).
//!
//! Friction work of a step: the work the bodies did on the spring minus the change of its energy. The
//! integrator (kick–drift–kick) applies the force of the previous evaluation and of this one for half a step
//! each, so the work done over the increment Δu = u_trial − u_prev is the trapezoid
//! ½ k_t (u_prev + u)·Δu, and the dissipation is
//!   D = ½ k_t (u_prev + u)·Δu − ½ k_t (|u|² − |u_prev|²) = ½ k_t (u_prev + u)·(u_trial − u),
//! zero while sticking (u = u_trial). The rectangle μ F_n |u_trial − u| (the force at the end of the step
//! times the slip) is the same in steady sliding but differs by ½ ΔF_t·Δu per step while the cap changes, a
//! first-order error that does not cancel over an impact: it under-counted the friction work of a spinning
//! sphere bouncing on a wall by 6 % at Δt = t_c/83, which the ledger showed as lost energy.
//!
//! Spring energy: ½ k_t |u|² (exact for a constant k_t; for the Mindlin k_t ∝ δ^(1/2) it is the usual
//! instantaneous estimate, as YADE's `shearEnergy`).
//!
//! # Work of the stiffness change (Mindlin)
//! When k_t follows the overlap, the force F_t = −k_t(δ) u is not the gradient of ½ k_t |u|²: continuously,
//! d(½ k_t |u|²) = k_t u·du + ½ |u|² dk_t, and only the first part is work done by the bodies on the
//! spring. The second is energy the law itself puts into (dk_t > 0) or takes out of (dk_t < 0) the stored
//! tangential energy, of either sign, and it is neither friction nor a potential (summed over a contact
//! that opens and closes again it does not vanish). Discretely, with the force −k_t^n u_n applied for the
//! first half of the step and −k_t^(n+1) u_(n+1) for the second, the balance of one step is exact with
//!   W_k = ½ (k_t^(n+1) − k_t^n) u_prev·u_trial
//! (u_prev the rotated previous displacement, u_trial = u_prev + v_t Δt): work of the bodies on the spring
//! ½ (k_t^n u_prev + k_t^(n+1) u)·Δu = change of ½ k_t |u|² + D − W_k. The law reports W_k as
//! [`TangentialResponse::stiffness_work`] and keeps k_t^n in the history; the ledger books it as its own
//! term ([`crate::world::EnergyLedger::tangential_stiffness_work`]). For a constant k_t it is zero.
//!
//! When a contact opens, the spring force of its last evaluation still acts for half a step; the
//! separation is booked by [`release_spring`] as one more evaluation with no normal force (so the cap
//! takes u to zero) and the stiffness at zero overlap (k_t for a constant spring, 0 for Mindlin).
//!
//! Pair order: the history belongs to the ordered pair (A, B). If the caller swaps the order, n and u change
//! sign: use [`TangentialHistory::swapped`].

use super::{check_range, LawError};
use crate::math::{Real, Vector};

/// The per-contact tangential state, stored by the caller (the contact store), keyed by the ordered pair.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct TangentialHistory {
    /// Accumulated tangential displacement of B relative to A (m), world frame.
    pub displacement: Vector,
    /// The contact normal (A → B) the displacement was last expressed in; zero for a new contact.
    pub normal: Vector,
    /// The stiffness k_t (N/m) the displacement was last evaluated with; zero for a new contact (see
    /// the module docs: the work of the stiffness change needs the previous k_t).
    pub stiffness: Real,
}

impl TangentialHistory {
    /// Whether every field holds the bits of [`TangentialHistory::default`] (+0.0: a spring with a −0.0
    /// component is not cleared, so that skipping the store of a cleared spring never changes a bit).
    #[inline(always)]
    pub fn is_cleared(&self) -> bool {
        let (u, n) = (&self.displacement, &self.normal);
        (u.x.to_bits() | u.y.to_bits() | u.z.to_bits())
            | (n.x.to_bits() | n.y.to_bits() | n.z.to_bits())
            | self.stiffness.to_bits()
            == 0
    }

    /// The same history seen from the swapped pair (B, A).
    pub fn swapped(&self) -> Self {
        Self {
            displacement: -self.displacement,
            normal: -self.normal,
            stiffness: self.stiffness,
        }
    }
}

/// How the stored spring is carried into the current tangent plane before this step's increment (the
/// normal turns a little every step).
///
/// - `Exact` (the default: the engine's rule since the start, with which every recorded comparison was
///   made): the smallest rotation taking the stored normal to the current one ([`rotate_into_tangent_plane`],
///   Rodrigues, then the round-off normal part removed with |u| kept); a few square roots and divisions
///   per contact and step.
/// - `Projection`: the normal component of u along the current normal is removed, u ← u − n (u·n)
///   ([`project_into_tangent_plane`]), |u| not restored: the rule of LIGGGHTS' `tangential history`
///   model (it adds v_t Δt first and projects the sum; v_t is tangential, so the two orders differ only
///   by round-off) and of LAMMPS' granular pair styles. Per step the spring shortens by the factor
///   cos Δθ of the normal's turn Δθ (second order: Δθ ~ |v_t| Δt / R, 1 − cos Δθ ~ 1e-7 in the sphere-bed
///   scenes); no square root, no division.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpringRotation {
    /// Rotate u rigidly with the normal, keeping |u| (see the type docs).
    #[default]
    Exact,
    /// Project u into the new tangent plane, as LIGGGHTS and LAMMPS do (see the type docs).
    Projection,
}

/// The tangential slot. `rotation` (absent in a serialised law: [`SpringRotation::Exact`]) says how the
/// spring follows the turning normal.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum TangentialLaw {
    /// Frictionless.
    None,
    /// Constant stiffness k_t (N/m) and friction coefficient μ.
    Spring {
        /// Tangential stiffness k_t (N/m).
        stiffness: Real,
        /// Coulomb friction coefficient μ ≥ 0.
        friction: Real,
        /// How the spring follows the turning normal.
        #[serde(default)]
        rotation: SpringRotation,
    },
    /// Mindlin no-slip stiffness k_t = coefficient · δ^(1/2) (coefficient = 8 G* √R*, N/m^1.5), friction μ.
    Mindlin {
        /// 8 G* √R* (N/m^1.5), so that k_t = coefficient · δ^(1/2).
        coefficient: Real,
        /// Coulomb friction coefficient μ ≥ 0.
        friction: Real,
        /// How the spring follows the turning normal.
        #[serde(default)]
        rotation: SpringRotation,
    },
    /// The Mindlin spring with a tangential dashpot while sticking, as LIGGGHTS' `model hertz tangential
    /// history` (`tangential_damping on`): F_t = −k_t u − c_t v_t with c_t = damping · √(m* k_t) (the
    /// dimensionless `damping` is 2√(5/6) β for LIGGGHTS, β = −ln e/√(π² + ln² e)); when |k_t u| exceeds
    /// μ F_n the force is capped at μ F_n along −u and the dashpot is off for that step.
    DampedMindlin {
        /// 8 G* √R* (N/m^1.5), so that k_t = coefficient · δ^(1/2).
        coefficient: Real,
        /// Coulomb friction coefficient μ ≥ 0.
        friction: Real,
        /// Dimensionless tangential damping (c_t = damping · √(m* k_t)).
        damping: Real,
        /// How the spring follows the turning normal.
        #[serde(default)]
        rotation: SpringRotation,
    },
}

impl TangentialLaw {
    /// Validated constant-stiffness spring.
    pub fn spring(stiffness: Real, friction: Real) -> Result<Self, LawError> {
        check_range(
            "tangential stiffness k_t",
            stiffness,
            0.0,
            Real::MAX,
            true,
            "(0, ∞)",
        )?;
        check_range("friction μ", friction, 0.0, Real::MAX, false, "[0, ∞)")?;
        Ok(Self::Spring {
            stiffness,
            friction,
            rotation: SpringRotation::Exact,
        })
    }

    /// How the spring follows the turning normal ([`SpringRotation::Exact`] without a spring).
    #[inline(always)]
    pub fn rotation(&self) -> SpringRotation {
        match *self {
            Self::None => SpringRotation::Exact,
            Self::Spring { rotation, .. }
            | Self::Mindlin { rotation, .. }
            | Self::DampedMindlin { rotation, .. } => rotation,
        }
    }

    /// The same law with the spring carried by `rotation` (no effect on [`TangentialLaw::None`]).
    pub fn with_rotation(mut self, rotation: SpringRotation) -> Self {
        match &mut self {
            Self::None => {}
            Self::Spring { rotation: r, .. }
            | Self::Mindlin { rotation: r, .. }
            | Self::DampedMindlin { rotation: r, .. } => *r = rotation,
        }
        self
    }

    /// The tangential stiffness (N/m) the time-step guard bounds: k_t of a constant spring; zero without a
    /// spring, and for the Mindlin springs, which the guard bounds through the normal law: their
    /// k_t = 8 G* √(R* δ) is 4G*/E* times the Hertz tangent stiffness 2 E* √(R* δ), a ratio
    /// 2(1 − ν)/(2 − ν) ≤ 1 for two bodies of one material with ν ≥ 0.
    pub fn stability_stiffness(&self) -> Real {
        match *self {
            Self::Spring { stiffness, .. } => stiffness,
            Self::None | Self::Mindlin { .. } | Self::DampedMindlin { .. } => 0.0,
        }
    }

    /// Whether the spring can carry no force (μ = 0): the `frictionless_history` skip may drop it
    /// (`crate::world::skips`).
    pub fn is_frictionless(&self) -> bool {
        self.stiffness_and_friction(0.0).1 == 0.0
    }

    /// The tangential stiffness (N/m) at overlap δ, and μ.
    pub fn stiffness_and_friction(&self, overlap: Real) -> (Real, Real) {
        match *self {
            Self::None => (0.0, 0.0),
            Self::Spring {
                stiffness,
                friction,
                ..
            } => (stiffness, friction),
            Self::Mindlin {
                coefficient,
                friction,
                ..
            }
            | Self::DampedMindlin {
                coefficient,
                friction,
                ..
            } => (coefficient * overlap.max(0.0).sqrt(), friction),
        }
    }
}

/// The result of one tangential evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentialResponse {
    /// Tangential force on B (N), world frame.
    pub force: Vector,
    /// True when the Coulomb cap was active.
    pub sliding: bool,
    /// Friction work dissipated in this step (J): the discrete work of the module docs, ≥ 0 except in a
    /// step whose increment reverses a sliding spring past zero while the cap drops (then the trapezoid of
    /// a sign-changing force is what the integrator did, and the ledger follows it).
    pub friction_dissipation: Real,
    /// Spring energy ½ k_t |u|² after the step (J).
    pub spring_energy: Real,
    /// Power dissipated by the tangential dashpot, c_t |v_t|² (W, ≥ 0; zero without one or when sliding).
    pub damping_power: Real,
    /// The dashpot's part of `force`, −c_t v_t (N; zero without one or when sliding).
    pub damping_force: Vector,
    /// Work of the stiffness change in this step, ½ (k_t − k_t,prev) u_prev·u_trial (J, either sign; zero
    /// for a constant k_t; see the module docs).
    pub stiffness_work: Real,
    /// u_prev: the stored displacement rotated into the current tangent plane (m), before this step's
    /// increment.
    pub previous_displacement: Vector,
}

impl TangentialResponse {
    /// The response of a contact without a tangential law: no force, no spring, no work.
    pub const NONE: TangentialResponse = TangentialResponse {
        force: Vector::new(0.0, 0.0, 0.0),
        sliding: false,
        friction_dissipation: 0.0,
        spring_energy: 0.0,
        damping_power: 0.0,
        damping_force: Vector::new(0.0, 0.0, 0.0),
        stiffness_work: 0.0,
        previous_displacement: Vector::new(0.0, 0.0, 0.0),
    };
}

/// Rotates the displacement `u` expressed against `old_normal` into the plane perpendicular to `new_normal`
/// (smallest rotation taking one normal to the other), keeping its length. A zero `old_normal` (new contact)
/// only projects.
#[inline(always)]
pub fn rotate_into_tangent_plane(u: &Vector, old_normal: &Vector, new_normal: &Vector) -> Vector {
    let length = u.norm();
    if length == 0.0 {
        return Vector::zeros();
    }
    let mut rotated = *u;
    let axis = old_normal.cross(new_normal);
    let sin = axis.norm();
    let cos = old_normal.dot(new_normal);
    if sin > 0.0 && old_normal.norm_squared() > 0.0 {
        // Rodrigues with unit axis k = axis/sin: v cosθ + (k × v) sinθ + k (k·v)(1 − cosθ).
        let k = axis / sin;
        rotated = u * cos + k.cross(u) * sin + k * (k.dot(u) * (1.0 - cos));
    }
    // Remove round-off (or, for an opposite or unknown old normal, the whole) normal component.
    rotated -= new_normal * rotated.dot(new_normal);
    let projected = rotated.norm();
    if projected == 0.0 {
        Vector::zeros()
    } else {
        rotated * (length / projected)
    }
}

/// The displacement `u` with its component along `new_normal` removed, u − n (u·n): the
/// [`SpringRotation::Projection`] rule (the length is not restored; see there).
#[inline(always)]
pub fn project_into_tangent_plane(u: &Vector, new_normal: &Vector) -> Vector {
    u - new_normal * u.dot(new_normal)
}

/// The stored spring `u` (expressed against `old_normal`) carried into the plane perpendicular to
/// `new_normal` by the rule `rotation`.
#[inline(always)]
pub fn carry_into_tangent_plane(
    rotation: SpringRotation,
    u: &Vector,
    old_normal: &Vector,
    new_normal: &Vector,
) -> Vector {
    match rotation {
        SpringRotation::Exact => rotate_into_tangent_plane(u, old_normal, new_normal),
        SpringRotation::Projection => project_into_tangent_plane(u, new_normal),
    }
}

/// One incremental step of the spring with Coulomb cap (see the module docs). `normal_force` is the
/// compressive normal force magnitude (negative values are treated as zero: no friction without
/// compression). `history` is updated in place.
pub fn incremental_spring(
    stiffness: Real,
    friction: Real,
    normal: &Vector,
    normal_force: Real,
    tangential_velocity: &Vector,
    dt: Real,
    history: &mut TangentialHistory,
) -> TangentialResponse {
    incremental_spring_damped(
        SpringRotation::Exact,
        stiffness,
        friction,
        0.0,
        normal,
        normal_force,
        tangential_velocity,
        dt,
        history,
    )
}

/// [`incremental_spring`] with the spring carried by `rotation` ([`carry_into_tangent_plane`]) and a
/// tangential dashpot c_t (N s/m) that acts while the contact sticks:
/// F_t = −k_t u − c_t v_t when k_t |u| ≤ μ F_n; otherwise the spring force is capped as without the dashpot
/// (the LIGGGHTS `tangential history` order). The dashpot's power c_t |v_t|² is reported in
/// [`TangentialResponse::damping_power`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn incremental_spring_damped(
    rotation: SpringRotation,
    stiffness: Real,
    friction: Real,
    damping: Real,
    normal: &Vector,
    normal_force: Real,
    tangential_velocity: &Vector,
    dt: Real,
    history: &mut TangentialHistory,
) -> TangentialResponse {
    let u_previous =
        carry_into_tangent_plane(rotation, &history.displacement, &history.normal, normal);
    let mut u = u_previous + tangential_velocity * dt;
    let stiffness_work = 0.5 * (stiffness - history.stiffness) * u_previous.dot(&u);
    let mut force = -stiffness * u;
    let cap = friction * normal_force.max(0.0);
    // The Coulomb cap without a branch on whether the contact slides (that branch was mispredicted for
    // ~4 contacts in 10 on the sphere beds): force and spring scaled by min(1, cap / |F|), 1 exactly
    // for a sticking contact (and for |F| = 0, where the quotient is ∞ or NaN), so a sticking contact
    // keeps its bits.
    let magnitude = force.norm();
    let sliding = magnitude > cap;
    let scale = (cap / magnitude).min(1.0);
    force *= scale;
    let u_capped = u * scale;
    let friction_dissipation = 0.5 * stiffness * (u_previous + u_capped).dot(&(u - u_capped));
    u = u_capped;
    let mut damping_power = 0.0;
    let mut damping_force = Vector::zeros();
    if damping > 0.0 {
        // The dashpot acts while the contact sticks: its coefficient times 1 or 0.
        let dashpot = damping * Real::from(u8::from(!sliding));
        damping_force = -dashpot * tangential_velocity;
        force += damping_force;
        damping_power = dashpot * tangential_velocity.norm_squared();
    }
    history.displacement = u;
    history.normal = *normal;
    history.stiffness = stiffness;
    TangentialResponse {
        force,
        sliding,
        friction_dissipation,
        spring_energy: 0.5 * stiffness * u.norm_squared(),
        damping_power,
        damping_force,
        stiffness_work,
        previous_displacement: u_previous,
    }
}

/// The step in which a contact opens: the spring of `history` (force −k_t,prev u on B for the first half
/// of the step) is released as by one more evaluation with no normal force and the stiffness
/// `end_stiffness` (the law's k_t at zero overlap). `relative_velocity` is v_B − v_A at the half step at
/// the last contact point; its part along the stored normal is dropped. Returns (friction dissipation,
/// stiffness work) in J, as [`TangentialResponse`]; the history is reset.
pub fn release_spring(
    end_stiffness: Real,
    relative_velocity: &Vector,
    dt: Real,
    history: &mut TangentialHistory,
) -> (Real, Real) {
    let u_previous = history.displacement;
    let n = history.normal;
    let v_t = relative_velocity - n * relative_velocity.dot(&n);
    let u_trial = u_previous + v_t * dt;
    let overlap = u_previous.dot(&u_trial);
    // The cap is zero: u goes to 0, D = ½ k_end (u_prev + 0)·(u_trial − 0).
    let friction_dissipation = 0.5 * end_stiffness * overlap;
    let stiffness_work = 0.5 * (end_stiffness - history.stiffness) * overlap;
    *history = TangentialHistory::default();
    (friction_dissipation, stiffness_work)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The guard bounds a constant spring by its k_t and leaves the Mindlin springs to the normal law.
    #[test]
    fn stability_stiffness_is_the_constant_spring_only() {
        assert_eq!(
            TangentialLaw::spring(2e5, 0.3)
                .unwrap()
                .stability_stiffness(),
            2e5
        );
        let mindlin = TangentialLaw::Mindlin {
            coefficient: 1e9,
            friction: 0.3,
            rotation: SpringRotation::Exact,
        };
        assert_eq!(mindlin.stability_stiffness(), 0.0);
        assert_eq!(TangentialLaw::None.stability_stiffness(), 0.0);
        assert!(TangentialLaw::spring(2e5, 0.0).unwrap().is_frictionless());
        assert!(!mindlin.is_frictionless());
    }
    use crate::math::Rotation;

    /// The cap without a branch gives what the branch on |F| > μ F_n gave: a sticking spring keeps its
    /// bits (force −k_t u, spring u, the dashpot added), a sliding one is scaled to the cap (|F| = μ F_n
    /// and u = −F/k_t to rounding, no dashpot), on random springs over 40 decades and on the edges
    /// (no spring, no cap, a NaN force).
    #[test]
    fn branchless_cap_slides_and_sticks_as_the_branch() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(23);
        let normal = Vector::z();
        let run = |u0: Vector, v_t: Vector, k: Real, mu: Real, f_n: Real, c_t: Real| {
            let mut history = TangentialHistory {
                displacement: u0,
                normal,
                stiffness: k,
            };
            let r = incremental_spring_damped(
                SpringRotation::Projection,
                k,
                mu,
                c_t,
                &normal,
                f_n,
                &v_t,
                1e-6,
                &mut history,
            );
            (r, history.displacement)
        };
        let (mut sliding, mut sticking) = (0, 0);
        for _ in 0..100_000 {
            let size = 10f64.powf(rng.random_range(-20.0..20.0));
            let mut random = || {
                Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                )
            };
            let (u0, v_t) = (random() * size, random() * size * 1e6);
            let k = 10f64.powf(rng.random_range(0.0..8.0));
            let f_n = k * size * rng.random_range(0.0..4.0);
            let (mu, c_t) = (0.3, if rng.random_bool(0.5) { 0.0 } else { 1e-3 * k });
            let (r, u) = run(u0, v_t, k, mu, f_n, c_t);
            let u_trial = u0 + v_t * 1e-6;
            let f_trial = -k * u_trial;
            let cap = mu * f_n;
            let expect_sliding = f_trial.norm() > cap;
            assert_eq!(
                r.sliding, expect_sliding,
                "u {u_trial:?}, k {k:e}, cap {cap:e}"
            );
            if expect_sliding {
                sliding += 1;
                let tol = 1e-14 * cap.max(Real::MIN_POSITIVE);
                assert!(
                    (r.force.norm() - cap).abs() <= tol,
                    "sliding: |F| {:e}, cap {cap:e}, tolerance {tol:e}",
                    r.force.norm()
                );
                let u_expected = -r.force / k;
                assert!(
                    (u - u_expected).norm() <= 1e-14 * u_expected.norm(),
                    "sliding: u {u:?}, -F/k {u_expected:?}"
                );
                assert_eq!(r.damping_force.norm(), 0.0, "no dashpot while sliding");
            } else {
                sticking += 1;
                let damping = -c_t * v_t;
                let expected = if c_t > 0.0 {
                    f_trial + damping
                } else {
                    f_trial
                };
                assert_eq!(
                    r.force, expected,
                    "sticking: same bits, u {u_trial:?}, k {k:e}"
                );
                assert_eq!(u, u_trial, "sticking: the spring keeps its bits");
            }
        }
        assert!(
            sliding > 10_000 && sticking > 10_000,
            "{sliding} sliding, {sticking} sticking"
        );
        // No spring: nothing slides. No cap, or a NaN normal force (no compression): the spring goes.
        let (r, u) = run(Vector::zeros(), Vector::zeros(), 1e5, 0.3, 0.0, 0.0);
        assert!(!r.sliding && r.force == Vector::zeros() && u == Vector::zeros());
        let (r, u) = run(Vector::x() * 1e-6, Vector::zeros(), 1e5, 0.3, 0.0, 0.0);
        assert!(
            r.sliding && r.force.norm() == 0.0 && u.norm() == 0.0,
            "{r:?} {u:?}"
        );
        let (r, u) = run(
            Vector::x() * 1e-6,
            Vector::zeros(),
            1e5,
            0.3,
            Real::NAN,
            0.0,
        );
        assert!(
            r.sliding && r.force.norm() == 0.0 && u.norm() == 0.0,
            "{r:?} {u:?}"
        );
    }

    #[test]
    fn only_the_bits_of_the_default_history_count_as_cleared() {
        assert!(TangentialHistory::default().is_cleared());
        let mut fields: Vec<(&str, TangentialHistory)> = Vec::new();
        for (name, value) in [("a tiny displacement", 1e-300), ("a negative zero", -0.0)] {
            let mut h = TangentialHistory::default();
            h.displacement.y = value;
            fields.push((name, h));
            let mut h = TangentialHistory::default();
            h.normal.z = value;
            fields.push((name, h));
            let h = TangentialHistory {
                stiffness: value,
                ..TangentialHistory::default()
            };
            fields.push((name, h));
        }
        for (what, h) in fields {
            assert!(
                !h.is_cleared(),
                "a history with {what} ({h:?}) reported as cleared: skipping its store would keep it"
            );
        }
    }

    #[test]
    fn spring_is_rotated_rigidly_with_the_normal() {
        let n_old = Vector::new(0.0, 0.0, 1.0);
        let u = Vector::new(2e-5, -1e-5, 0.0);
        let turn = Rotation::from_scaled_axis(Vector::new(0.3, -0.2, 0.0));
        let n_new = turn.transform_vector(&n_old);
        let rotated = rotate_into_tangent_plane(&u, &n_old, &n_new);
        // The smallest rotation taking n_old to n_new is `turn` itself (its axis is perpendicular to n_old).
        let expected = turn.transform_vector(&u);
        assert!(
            (rotated - expected).norm() < 1e-15 * u.norm() * 10.0,
            "rotated spring {rotated:?}, expected {expected:?}"
        );
        assert!(
            rotated.dot(&n_new).abs() < 1e-16 * u.norm() * 10.0,
            "spring not in the new tangent plane"
        );
        assert!(
            (rotated.norm() - u.norm()).abs() < 1e-15 * u.norm() * 10.0,
            "length changed"
        );
    }

    #[test]
    fn coulomb_cap_limits_the_force_and_counts_the_slip_work() {
        let normal = Vector::new(0.0, 0.0, 1.0);
        let (k, mu, fn_) = (1e5, 0.3, 10.0);
        let mut history = TangentialHistory::default();
        let v = Vector::new(0.21, 0.0, 0.0);
        let dt = 1e-5;
        let mut dissipated = 0.0;
        let mut slip_onset = None;
        for step in 0..200 {
            let r = incremental_spring(k, mu, &normal, fn_, &v, dt, &mut history);
            assert!(
                r.force.norm() <= mu * fn_ * (1.0 + 1e-15),
                "|F_t| = {} above μF_n = {}",
                r.force.norm(),
                mu * fn_
            );
            if r.sliding && slip_onset.is_none() {
                slip_onset = Some(step);
            }
            dissipated += r.friction_dissipation;
        }
        // Sticking while k|u| ≤ μF_n = 3 N: after step i, k|u| = 0.21 (i + 1) N, first above 3 N at i = 14.
        let onset = slip_onset.expect("never slid");
        assert_eq!(
            onset, 14,
            "slip onset at step {onset}, expected 14 (k v Δt (i+1) > μ F_n)"
        );
        // Discrete work balance: the trapezoidal work of the force over the 200 increments (k u per step:
        // 0.21 (i + 1) N while sticking, 3 N from the onset on) minus the final spring energy ½ (μF_n)²/k.
        let increment = v.norm() * dt;
        let force_after = |i: usize| (k * increment * (i + 1) as f64).min(mu * fn_);
        let work: f64 = (0..200)
            .map(|i| {
                let before = if i == 0 { 0.0 } else { force_after(i - 1) };
                0.5 * (before + force_after(i)) * increment
            })
            .sum();
        let expected = work - 0.5 * (mu * fn_).powi(2) / k;
        assert!(
            (dissipated - expected).abs() < 1e-12 * expected,
            "dissipated {dissipated}, expected trapezoidal work − spring energy = {expected}"
        );
        // The continuous answer μF_n · slip (slip = total displacement − stretch at the cap) differs from it by
        // less than one step's change of force times one increment.
        let slip = increment * 200.0 - mu * fn_ / k;
        let continuous = mu * fn_ * slip;
        assert!(
            (dissipated - continuous).abs() <= 0.5 * k * increment * increment,
            "dissipated {dissipated}, continuous μF_n·slip = {continuous}, bound ½ k Δu² = {}",
            0.5 * k * increment * increment
        );
        // No compression, no friction.
        let mut h = TangentialHistory::default();
        let r = incremental_spring(k, mu, &normal, -5.0, &v, dt, &mut h);
        assert_eq!(r.force, Vector::zeros());
    }

    #[test]
    fn projection_removes_the_normal_part_and_shortens_by_the_cosine_of_the_turn() {
        let n_old = Vector::new(0.0, 0.0, 1.0);
        let u = Vector::new(2e-5, -1e-5, 0.0);
        let turn = Rotation::from_scaled_axis(Vector::new(0.3, -0.2, 0.0));
        let n_new = turn.transform_vector(&n_old);
        let projected = project_into_tangent_plane(&u, &n_new);
        assert!(
            projected.dot(&n_new).abs() < 1e-16 * u.norm() * 10.0,
            "projected spring {projected:?} not in the plane of {n_new:?}"
        );
        // |u − n(u·n)|² = |u|² − (u·n)²: the closed form of the projection's length.
        let expected = (u.norm_squared() - u.dot(&n_new).powi(2)).sqrt();
        assert!(
            (projected.norm() - expected).abs() < 1e-14 * u.norm(),
            "projected length {}, expected √(|u|² − (u·n)²) = {expected}",
            projected.norm()
        );
        // Against the exact rotation: the same direction in the plane to first order in the turn θ
        // (|θ| = 0.36 rad here), and never longer.
        let exact = rotate_into_tangent_plane(&u, &n_old, &n_new);
        let theta = 0.3_f64.hypot(0.2);
        assert!(
            projected.norm() <= exact.norm() * (1.0 + 1e-15),
            "projection {} longer than the rotated spring {}",
            projected.norm(),
            exact.norm()
        );
        assert!(
            (projected - exact).norm() <= (1.0 - theta.cos()) * u.norm() * (1.0 + 1e-9) + 1e-20,
            "projection {projected:?} and rotation {exact:?} differ by more than (1 − cos θ)|u|, θ = {theta}"
        );
        // The law with either rule on a fixed normal: the same force (nothing to carry).
        let normal = Vector::new(0.0, 0.0, 1.0);
        let v = Vector::new(0.1, 0.05, 0.0);
        let (mut h1, mut h2) = (TangentialHistory::default(), TangentialHistory::default());
        let spring = |rule, history: &mut TangentialHistory| {
            incremental_spring_damped(rule, 1e5, 0.3, 0.0, &normal, 10.0, &v, 1e-5, history)
        };
        for _ in 0..5 {
            let a = spring(SpringRotation::Exact, &mut h1);
            let b = spring(SpringRotation::Projection, &mut h2);
            assert_eq!(
                a.force, b.force,
                "fixed normal: exact {a:?}, projection {b:?}"
            );
        }
    }

    #[test]
    fn swapping_the_pair_flips_the_history() {
        let h = TangentialHistory {
            displacement: Vector::new(1e-6, 2e-6, 0.0),
            normal: Vector::new(0.0, 0.0, 1.0),
            stiffness: 3e4,
        };
        let s = h.swapped();
        assert_eq!(s.displacement, -h.displacement);
        assert_eq!(s.normal, -h.normal);
        assert_eq!(s.swapped(), h);
    }
}
