//! The slot composition `ContactModel { normal, damping, tangential }` evaluated on one contact.
//!
//! Inputs: the [`ContactGeometry`] of the pair (A, B) (Minkowski overlap δ_M, normal n_M from A to B, contact
//! point c_M) and the [`ContactKinematics`] (relative velocity of B with respect to A at c_M, effective mass,
//! centres of mass for the torques, time step for the tangential increment). Output: the force on B at c_M
//! (A receives the opposite), the torques about each centre of mass, and the energy terms the ledger needs.

use super::damping::DampingLaw;
use super::normal::NormalLaw;
use super::tangential::{incremental_spring, TangentialHistory, TangentialLaw};
use crate::contact::{ContactGeometry, ContactKind};
use crate::math::{Point, Real, Vector};

/// One contact model, composed by slot.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactModel {
    pub normal: NormalLaw,
    pub damping: DampingLaw,
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
    /// Power dissipated by the normal damping, f_d δ̇ ≥ 0 (W).
    pub damping_power: Real,
    /// Friction work dissipated during this step (J, ≥ 0).
    pub friction_dissipation: Real,
    /// True when the Coulomb cap was active.
    pub sliding: bool,
}

impl ContactModel {
    /// Evaluates the model on one contact. `history` is the pair's tangential state (stored by the caller);
    /// it is reset when the shapes do not overlap.
    pub fn evaluate(
        &self,
        geometry: &ContactGeometry,
        kinematics: &ContactKinematics,
        history: &mut TangentialHistory,
    ) -> ContactResponse {
        if geometry.kind != ContactKind::Overlap || geometry.depth <= 0.0 {
            *history = TangentialHistory::default();
            return ContactResponse::default();
        }
        let n = geometry.normal;
        let overlap = geometry.depth;
        let v = kinematics.relative_velocity;
        let overlap_rate = -v.dot(&n);
        let (k, exponent) = (self.normal.stiffness, self.normal.exponent);
        let elastic = self.normal.force(overlap);
        let damping = self.damping.force(
            k,
            exponent,
            kinematics.effective_mass,
            overlap,
            overlap_rate,
        );
        let normal_force = elastic + damping;

        let (tangential_force, tangential_potential, friction_dissipation, sliding) =
            match self.tangential {
                TangentialLaw::None => (Vector::zeros(), 0.0, 0.0, false),
                law => {
                    let (stiffness, friction) = law.stiffness_and_friction(overlap);
                    let v_t = v - n * v.dot(&n);
                    let r = incremental_spring(
                        stiffness,
                        friction,
                        &n,
                        normal_force,
                        &v_t,
                        kinematics.dt,
                        history,
                    );
                    (r.force, r.spring_energy, r.friction_dissipation, r.sliding)
                }
            };
        let force_on_b = n * normal_force + tangential_force;
        let point = geometry.point;
        ContactResponse {
            force_on_b,
            torque_on_a: (point - kinematics.center_a).cross(&(-force_on_b)),
            torque_on_b: (point - kinematics.center_b).cross(&force_on_b),
            normal_force,
            tangential_force,
            normal_potential: self.normal.potential(overlap),
            tangential_potential,
            damping_power: damping * overlap_rate,
            friction_dissipation,
            sliding,
        }
    }
}
