//! A contact model with the constants of one contact formed: what [`ContactModel::evaluate`] computes
//! from the model and the effective mass before it looks at the overlap (the viscous damping's
//! ζ̂ √(m* k_n), the tangential dashpot's damping · √(m* k̂_t)), kept so that a caller that evaluates
//! the same pair over many steps (the flat sphere path's neighbour list) forms them once per pair
//! instead of once per step.
//!
//! [`ContactModel::evaluate`] is [`ContactModel::prepared`] followed by [`PreparedModel::respond`], so
//! the two ways of calling the law are the same operations in the same order, and give the same bits.

use super::damping::PreparedDamping;
use super::model::{ContactModel, ContactResponse};
use super::normal::NormalLaw;
use super::tangential::{
    incremental_spring_damped, TangentialHistory, TangentialLaw, TangentialResponse,
};
use crate::math::{Point, Real, Vector};

/// A [`ContactModel`] with the constants of one contact (its effective mass) formed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedModel {
    /// The normal slot (k_n as the caller scaled it for the contact's radii).
    pub normal: NormalLaw,
    /// The damping slot with this contact's constants formed.
    pub damping: PreparedDamping,
    /// The tangential slot.
    pub tangential: TangentialLaw,
    /// The tangential dashpot's c_t over δ^¼: damping · √(m* k̂_t) for [`TangentialLaw::DampedMindlin`]
    /// with k_t = k̂_t √δ (N s/m^(5/4)), zero for the other laws. Formed once per contact, so that an
    /// evaluation takes c_t from the δ^¼ the viscous normal damping also forms instead of a square root
    /// of m* k_t of its own (the two forms agree to rounding).
    pub tangential_dashpot: Real,
}

impl ContactModel {
    /// The model with the constants of a contact of effective mass `effective_mass` (kg) formed.
    #[inline(always)]
    pub fn prepared(&self, effective_mass: Real) -> PreparedModel {
        PreparedModel {
            normal: self.normal,
            damping: self.damping.prepared(self.normal.stiffness, effective_mass),
            tangential: self.tangential,
            tangential_dashpot: match self.tangential {
                TangentialLaw::DampedMindlin {
                    coefficient,
                    damping,
                    ..
                } => damping * (effective_mass * coefficient).sqrt(),
                _ => 0.0,
            },
        }
    }
}

impl PreparedModel {
    /// The law on an overlapping contact (overlap δ > 0, m; unit normal n from A to B; contact point c;
    /// relative velocity v_B − v_A at c, m/s; centres of A and B; the tangential increment's time Δt, s),
    /// updating the pair's spring `history`: [`ContactModel::evaluate`] past its test for an overlap.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn respond(
        &self,
        overlap: Real,
        n: &Vector,
        point: &Point,
        relative_velocity: &Vector,
        center_a: &Point,
        center_b: &Point,
        dt: Real,
        history: &mut TangentialHistory,
    ) -> ContactResponse {
        let n = *n;
        let v = *relative_velocity;
        let overlap_rate = -v.dot(&n);
        let elastic = self.normal.force(overlap);
        let mut damping = self
            .damping
            .force(self.normal.exponent, overlap, overlap_rate);
        if self.normal.never_attractive && elastic + damping < 0.0 {
            // The clamp removes the part of the damping force that would pull: what acts is −elastic.
            damping = -elastic;
        }
        let normal_force = elastic + damping;

        let (t, previous_displacement) = match self.tangential {
            TangentialLaw::None => (TangentialResponse::NONE, None),
            law => {
                let r = self.tangential_response(law, overlap, &n, &v, normal_force, dt, history);
                (r, Some(r.previous_displacement))
            }
        };
        let force_on_b = n * normal_force + t.force;
        ContactResponse {
            force_on_b,
            torque_on_a: (point - center_a).cross(&(-force_on_b)),
            torque_on_b: (point - center_b).cross(&force_on_b),
            normal_force,
            tangential_force: t.force,
            normal_potential: self.normal.potential(overlap),
            tangential_potential: t.spring_energy,
            damping_power: damping * overlap_rate + t.damping_power,
            damping_force: n * damping + t.damping_force,
            friction_dissipation: t.friction_dissipation,
            tangential_stiffness_work: t.stiffness_work,
            sliding: t.sliding,
            previous_displacement,
        }
    }

    /// The tangential slot `law` (not [`TangentialLaw::None`]) at overlap δ with unit normal `n`,
    /// relative velocity `v` and normal force `normal_force`: the spring `history` advanced over `dt`
    /// with the law's stiffness, Coulomb cap and dashpot at δ.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn tangential_response(
        &self,
        law: TangentialLaw,
        overlap: Real,
        n: &Vector,
        v: &Vector,
        normal_force: Real,
        dt: Real,
        history: &mut TangentialHistory,
    ) -> TangentialResponse {
        let (stiffness, friction) = law.stiffness_and_friction(overlap);
        let dashpot = match law {
            TangentialLaw::DampedMindlin { .. } => {
                self.tangential_dashpot * overlap.max(0.0).sqrt().sqrt()
            }
            _ => 0.0,
        };
        let v_t = v - n * v.dot(n);
        incremental_spring_damped(
            law.rotation(),
            stiffness,
            friction,
            dashpot,
            n,
            normal_force,
            &v_t,
            dt,
            history,
        )
    }
}
