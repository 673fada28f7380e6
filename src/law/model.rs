//! The slot composition `ContactModel { normal, damping, tangential }` evaluated on one contact.
//!
//! Inputs: the [`ContactGeometry`] of the pair (A, B) (Minkowski overlap δ_M, normal n_M from A to B, contact
//! point c_M) and the [`ContactKinematics`] (relative velocity of B with respect to A at c_M, effective mass,
//! centres of mass for the torques, time step for the tangential increment). Output: the force on B at c_M
//! (A receives the opposite), the torques about each centre of mass, and the energy terms the ledger needs.

use super::damping::DampingLaw;
use super::normal::NormalLaw;
use super::tangential::{TangentialHistory, TangentialLaw};
use crate::contact::{ContactGeometry, ContactKind};
use crate::math::{Point, Real, Vector};

/// One contact model, composed by slot.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactModel {
    /// The normal force as a function of the overlap.
    pub normal: NormalLaw,
    /// The normal damping force.
    pub damping: DampingLaw,
    /// The tangential (friction) force and its history.
    pub tangential: TangentialLaw,
}

/// Motion of the pair at the contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactKinematics {
    /// v_B(c_M) − v_A(c_M) (m/s), world frame, including the rotational parts ω × (c_M − x).
    pub relative_velocity: Vector,
    /// m* = m_A m_B/(m_A + m_B) (kg); m_A for a body against a fixed one.
    pub effective_mass: Real,
    /// Centre of mass of A (m).
    pub center_a: Point,
    /// Centre of mass of B (m).
    pub center_b: Point,
    /// Time step (s), for the tangential increment v_t Δt.
    pub dt: Real,
}

/// Forces, torques and energy terms of one contact evaluation. All zero when the shapes do not overlap.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ContactResponse {
    /// Total force on B (N), applied at c_M; the force on A is its opposite.
    pub force_on_b: Vector,
    /// Torque on A about its centre of mass (N·m): (c_M − x_A) × (−F).
    pub torque_on_a: Vector,
    /// Torque on B about its centre of mass (N·m): (c_M − x_B) × F.
    pub torque_on_b: Vector,
    /// Normal force magnitude, elastic + damping (N, positive in compression).
    pub normal_force: Real,
    /// Tangential force on B (N).
    pub tangential_force: Vector,
    /// Elastic potential of the normal law, k_n δ^(n+1)/(n+1) (J).
    pub normal_potential: Real,
    /// Tangential spring energy ½ k_t |u|² (J).
    pub tangential_potential: Real,
    /// Power dissipated by the normal damping, f_d δ̇ (W, ≥ 0 unless the force limit clamps it), plus that
    /// of a tangential dashpot, at this evaluation (the ledger books the work of `damping_force` instead,
    /// see [`crate::world::energy`]).
    pub damping_power: Real,
    /// The velocity-dependent part of `force_on_b` (N): the normal damping n f_d (as clamped by the force
    /// limit) plus the tangential dashpot.
    pub damping_force: Vector,
    /// Friction work dissipated during this step (J, ≥ 0).
    pub friction_dissipation: Real,
    /// Work of the change of the tangential stiffness during this step (J, either sign; see
    /// [`super::tangential`]): energy the Mindlin law puts into its stored tangential energy.
    pub tangential_stiffness_work: Real,
    /// True when the Coulomb cap was active.
    pub sliding: bool,
    /// The spring of the last evaluation rotated into this evaluation's tangent plane (u_prev of
    /// [`super::tangential`], m), as the tangential law formed it; `None` without a tangential law. The
    /// energy ledger books the last spring force along it (see [`crate::world::energy`]).
    pub previous_displacement: Option<Vector>,
}

impl ContactModel {
    /// The model with the slots the step's skips make free (`crate::world::skips`): no tangential spring
    /// when `frictionless_history` and μ = 0, no damping term when `undamped_contacts` and its coefficient
    /// is 0. The forces are the same up to the sign of zero.
    pub fn with_skips(&self, frictionless_history: bool, undamped_contacts: bool) -> ContactModel {
        let mut m = *self;
        if frictionless_history && m.tangential.is_frictionless() {
            m.tangential = TangentialLaw::None;
        }
        if undamped_contacts && m.damping.has_zero_coefficient() {
            m.damping = DampingLaw::None;
        }
        m
    }

    /// Evaluates the model on one contact. `history` is the pair's tangential state (stored by the caller);
    /// it is reset when the shapes do not overlap.
    #[inline]
    pub fn evaluate(
        &self,
        geometry: &ContactGeometry,
        kinematics: &ContactKinematics,
        history: &mut TangentialHistory,
    ) -> ContactResponse {
        self.evaluate_inlined(geometry, kinematics, history)
    }

    /// [`ContactModel::evaluate`], always inlined into its caller: the same operations, so the same bits,
    /// but a caller that reads only some fields of the response (the sphere kernel without the energy
    /// ledger: forces, torques, potentials) lets the compiler drop the work of the others.
    #[inline(always)]
    pub fn evaluate_inlined(
        &self,
        geometry: &ContactGeometry,
        kinematics: &ContactKinematics,
        history: &mut TangentialHistory,
    ) -> ContactResponse {
        if geometry.kind != ContactKind::Overlap || geometry.depth <= 0.0 {
            *history = TangentialHistory::default();
            return ContactResponse::default();
        }
        self.prepared(kinematics.effective_mass).respond(
            geometry.depth,
            &geometry.normal,
            &geometry.point,
            &kinematics.relative_velocity,
            &kinematics.center_a,
            &kinematics.center_b,
            kinematics.dt,
            history,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The skips drop a spring only when μ = 0 and a damping term only when its coefficient is 0; every
    /// other slot is kept as it is.
    #[test]
    fn skips_free_only_the_slots_that_carry_no_force() {
        let normal = NormalLaw::linear(1e6).unwrap();
        let frictionless = TangentialLaw::Spring {
            stiffness: 1e5,
            friction: 0.0,
            rotation: Default::default(),
        };
        let model = ContactModel {
            normal,
            damping: DampingLaw::Viscous { coefficient: 0.0 },
            tangential: frictionless,
        };
        let free = model.with_skips(true, true);
        assert_eq!(free.tangential, TangentialLaw::None, "model {model:?}");
        assert_eq!(free.damping, DampingLaw::None, "model {model:?}");
        assert_eq!(model.with_skips(false, false), model);
        let kept = ContactModel {
            normal,
            damping: DampingLaw::Dashpot { coefficient: 3.0 },
            tangential: TangentialLaw::spring(1e5, 0.4).unwrap(),
        };
        assert_eq!(kept.with_skips(true, true), kept);
        let zero_dashpot = ContactModel {
            damping: DampingLaw::Dashpot { coefficient: 0.0 },
            ..kept
        };
        assert_eq!(
            zero_dashpot.with_skips(false, true).damping,
            DampingLaw::None
        );
        assert_eq!(zero_dashpot.with_skips(true, false), zero_dashpot);
    }
    use crate::contact::SolverStatus;
    use crate::law::{DampingLaw, NormalLaw};

    /// Head-on impact of a point mass m* on the model at speed v₀, by velocity Verlet with `steps_per_unit`
    /// steps per δ₀/v₀; returns the rebound speed / v₀.
    fn simulated_restitution(model: &ContactModel, mass: Real, speed: Real) -> Real {
        let n = model.normal.exponent;
        let scale = (mass * speed * speed / model.normal.stiffness).powf(1.0 / (n + 1.0));
        let dt = scale / speed * 2e-5;
        let (mut x, mut v) = (0.0, speed); // x = overlap, v = overlap rate
        let mut history = TangentialHistory::default();
        let force = |x: Real, v: Real, h: &mut TangentialHistory| {
            let g = ContactGeometry::from_points(
                ContactKind::Overlap,
                x,
                -x,
                Vector::z(),
                Point::origin(),
                Point::origin(),
                SolverStatus::Converged,
            );
            let k = ContactKinematics {
                relative_velocity: Vector::z() * -v,
                effective_mass: mass,
                center_a: Point::new(0.0, 0.0, -1.0),
                center_b: Point::new(0.0, 0.0, 1.0),
                dt,
            };
            if x <= 0.0 {
                0.0
            } else {
                model.evaluate(&g, &k, h).normal_force
            }
        };
        let mut f = 0.0;
        loop {
            let v_half = v - 0.5 * dt * f / mass;
            x += dt * v_half;
            if x <= 0.0 {
                return -v_half / speed;
            }
            f = force(x, v_half, &mut history);
            v = v_half - 0.5 * dt * f / mass;
        }
    }

    /// The oracle: the dimensionless impact x'' = −max(x^n + ζ̂ x^a x', 0) by small explicit RK4 steps; with
    /// the force limit the bodies part when the force reaches zero, so e = −x' there.
    fn clamped_restitution_oracle(exponent: Real, coefficient: Real) -> Real {
        let a = 0.5 * (exponent - 1.0);
        let force =
            |x: Real, v: Real| x.max(0.0).powf(exponent) + coefficient * x.max(0.0).powf(a) * v;
        let acc = |x: Real, v: Real| -force(x, v).max(0.0);
        let (mut x, mut v): (Real, Real) = (0.0, 1.0);
        let h = 1e-5;
        loop {
            let (k1x, k1v) = (v, acc(x, v));
            let (k2x, k2v) = (v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
            let (k3x, k3v) = (v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
            let (k4x, k4v) = (v + h * k3v, acc(x + h * k3x, v + h * k3v));
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            if v < 0.0 && (force(x, v) <= 0.0 || x <= 0.0) {
                return -v;
            }
        }
    }

    #[test]
    fn force_limit_ends_the_contact_when_the_force_vanishes() {
        for (exponent, e) in [(1.5, 0.5), (1.5, 0.4), (1.0, 0.5)] {
            let base = ContactModel {
                normal: NormalLaw::new(2e8, exponent).unwrap(),
                damping: DampingLaw::from_restitution(exponent, e).unwrap(),
                tangential: TangentialLaw::None,
            };
            let free = simulated_restitution(&base, 1e-4, 5.0);
            assert!(
                (free - e).abs() < 2e-4,
                "n = {exponent}, e = {e}: without the limit the rebound is e = {free}, expected {e} (tolerance 2e-4)"
            );
            let limited = ContactModel {
                normal: base.normal.with_force_limit(),
                ..base
            };
            let measured = simulated_restitution(&limited, 1e-4, 5.0);
            let DampingLaw::Viscous { coefficient } = base.damping else {
                panic!("damped law expected")
            };
            let oracle = clamped_restitution_oracle(exponent, coefficient);
            assert!(
                (measured - oracle).abs() < 2e-4 && measured > e,
                "n = {exponent}, e = {e}: with the force limit the rebound is {measured}, oracle {oracle} (tolerance 2e-4)"
            );
        }
    }
}
