//! The energy ledger: where the energy of a run went, so that a run can be audited.
//!
//! At any state the mechanical energy is
//! E = T_trans + T_rot + U_elastic + U_gravity, with T summed over dynamic bodies (½ m|v|², ½ L̄·J̄⁻¹L̄),
//! U_elastic the sum of the contact laws' potentials (normal k_n δ^(n+1)/(n+1) and tangential ½ k_t |u|²) at
//! the current overlaps, and U_gravity = −Σ m g·x. The ledger accumulates, step by step:
//! - `dissipated_damping`: normal contact damping and the tangential dashpot, booked as the integrator
//!   applies them (below);
//! - `dissipated_friction`: the Coulomb slip work of the tangential spring (below);
//! - `tangential_stiffness_work`: the energy the Mindlin spring gains (or loses) because its stiffness
//!   follows the overlap, ½ |u|² Δk_t (below; zero for a constant k_t);
//! - `dissipated_viscous`: global viscous damping c|v|², trapezoidal over the step;
//! - `removed_by_sleeping`: the kinetic energy of bodies when they fell asleep (their velocities are then
//!   set to zero, see [`super::sleeping`]); part of the balance, not a column of [`EnergyReport`];
//! - `external_work`: the work done on the system by walls and non-dynamic bodies with a prescribed
//!   velocity, trapezoidal over the step (P = −F_on_wall·v_wall, both ends with the velocity that moves
//!   the wall in that step: a wall whose velocity is changed between steps, like the packing's servo-driven
//!   top wall, books the work it does. Taking the start of the step with the velocity of the previous
//!   evaluation booked ~2× the work of a bang-bang servo wall: the compaction ledgers missed 50–58 % of
//!   the wall's work).
//!
//! The balance E(t) + dissipated − external − tangential stiffness work − E(0) is zero for exact dynamics.
//!
//! # What the discrete step does to the energy
//! Kick–drift–kick with the loads F_n at x_n: v_(n+½) = v_n + Δt F_n/2m, x_(n+1) = x_n + Δt v_(n+½),
//! v_(n+1) = v_(n+½) + Δt F_(n+1)/2m, where F_(n+1) is evaluated at x_(n+1) with the half-step velocities
//! (damping, tangential increment). Then exactly
//!   ½ m |v_(n+1)|² − ½ m |v_n|² = ½ (F_n + F_(n+1))·Δt v_(n+½) + (Δt²/8m) (|F_(n+1)|² − |F_n|²),
//! and the same for the rotation (torques, ω at the half step; the free rotation of the drift keeps T_rot
//! to second order). The last term telescopes: over a run it is (Δt²/8m)(|F_end|² − |F_0|²), second
//! order. So the kinetic energy changes by the trapezoid of every force's work over the step, each
//! contact force acting on the relative motion of its contact point. For the conservative part (normal
//! elastic force, gravity) the trapezoid differs from −ΔU by the quadrature error, O(Δt³) per step; the
//! ledger books the non-conservative parts with the same trapezoid, so what is left in the balance is
//! that quadrature error and the telescoping term: **second order** (measured in
//! `tests/world_ledger_damping.rs`: fitted orders 1.87–2.06 from t_c/50 to t_c/200 on damped Hertz,
//! Hertz–Mindlin and linear dashpot scenes, with a cube, a moving wall or global viscous damping; sphere
//! bed a over its first 3 ms: 4.5e-5, 1.1e-5, 2.8e-6 J at Δt, Δt/2, Δt/4 without friction and 2.0e-5,
//! 5.0e-6, 1.3e-6 J with it, against 5.0e-4 and 2.4e-4 J at Δt and Δt/2 without friction before).
//!
//! Per contact and step (n → n+1), with v_prev the relative velocity of the pair at the half step at the
//! last contact point c_n with the lever arms c_n − x_n the last forces were applied with, and v the
//! relative velocity at the new point c_(n+1) (the one the law sees):
//! - damping: −½ Δt (f_d^n·v_prev + f_d^(n+1)·v), with f_d the velocity-dependent part of the force on B
//!   (normal damping as clamped by the force limit, plus the tangential dashpot), the last one kept per
//!   contact in [`super::ContactState::damping_force`]. The former booking ½ (P_n + P_(n+1)) Δt of the
//!   power f_d δ̇ at the evaluations was first order, lagging the force by half a step.
//! - friction: the law's slip work ([`crate::law::tangential`]: zero while sticking), which measures the
//!   spring increment with v in the new tangent plane, corrected by the work the last spring force
//!   −k_t^n u_n did with the integrator's lever arms (½ Δt f_s^n·v_prev) instead of the one the law's
//!   increment assumed (−½ Δt k_t^n u_n·v_t). The correction is first order in Δt (it vanishes as the
//!   contact point stops moving over a step) and makes the ledger of a spinning sphere sliding on a wall
//!   close to 2e-6 of the friction work at t_c/200 (`tests/world_ledger.rs`).
//! - tangential stiffness work: ½ (k_t^(n+1) − k_t^n) u_n·u_trial, reported by the law. It is kept out
//!   of the dissipated terms on purpose: it is energy the incremental Mindlin law creates or destroys
//!   in its stored tangential energy (F_t = −k_t(δ) u is not the gradient of ½ k_t |u|²), of either sign,
//!   and it is not a potential either (summed over a contact that opens and closes it does not vanish);
//!   it enters the balance like external work, done by the law rather than by a wall.
//! - a contact that opens in this step: its last forces acted for the first half kick. The ledger books
//!   −½ Δt f_d^n·v_prev and releases the spring as one more evaluation with no normal force and the
//!   law's stiffness at zero overlap (the cap takes u to zero: slip work ½ k_t,0 u_n·u_trial; stiffness
//!   work ½ (k_t,0 − k_t^n) u_n·u_trial; k_t,0 = k_t for a constant spring, 0 for Mindlin).
//!
//! Not booked: a pair that leaves the broad phase's candidate list while its last evaluation
//! overlapped (the store drops it without a release; the Verlet skin keeps overlapping pairs listed, so
//! this needs a body to cross the skin in one step); frozen pairs book nothing (their bodies do not
//! move). The external work stays the trapezoid of the power at the evaluations, the same trapezoid as
//! above for a wall or body of constant prescribed velocity (checked with the moving wall of
//! `tests/world_ledger_damping.rs`). The global viscous damping also stays the trapezoid
//! ½ c (|v_n|² + |v_(n+1)|²) Δt: the kicks apply −c v_n explicitly in the first half and −c v_(n+1)
//! implicitly in the second, and their work differs from the trapezoid by (Δt²/8) c (v_n·a_n −
//! v_(n+1)·a_(n+1)), which telescopes (measured: fitted order 1.93, same test).

use crate::law::tangential::{release_spring, rotate_into_tangent_plane};
use crate::law::{ContactResponse, TangentialHistory, TangentialLaw};
use crate::math::Real;
use crate::math::Vector;

/// Work accumulated since the start of the run (J).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnergyLedger {
    /// Mechanical energy at the first evaluation of the loads (J); `None` before it.
    pub(in crate::world) initial_total: Option<Real>,
    /// Work of the normal damping dissipated so far (J).
    pub(in crate::world) dissipated_damping: Real,
    /// Work of friction dissipated so far (J).
    pub(in crate::world) dissipated_friction: Real,
    /// Work of the global viscous damping dissipated so far (J).
    pub(in crate::world) dissipated_viscous: Real,
    /// Work done on the system by non-dynamic bodies and walls so far (J).
    pub(in crate::world) external_work: Real,
    /// Kinetic energy removed when bodies fell asleep (J).
    #[serde(default)]
    pub(in crate::world) removed_by_sleeping: Real,
    /// Work of the tangential stiffness change (Mindlin k_t ∝ δ^(1/2)) on the stored tangential energy
    /// (J, either sign; see [`crate::law::tangential`]): enters the balance like external work.
    #[serde(default)]
    pub(in crate::world) tangential_stiffness_work: Real,
}

impl EnergyLedger {
    /// Mechanical energy at the first evaluation of the loads (J); `None` before it (or after
    /// [`super::World::reset_ledger`]).
    pub fn initial_total(&self) -> Option<Real> {
        self.initial_total
    }

    /// Work of the normal damping and the tangential dashpot dissipated so far (J).
    pub fn dissipated_damping(&self) -> Real {
        self.dissipated_damping
    }

    /// Work of Coulomb friction dissipated so far (J).
    pub fn dissipated_friction(&self) -> Real {
        self.dissipated_friction
    }

    /// Work of the tangential stiffness change so far (J, either sign; enters the balance like external
    /// work).
    pub fn tangential_stiffness_work(&self) -> Real {
        self.tangential_stiffness_work
    }

    /// Work of the global viscous damping dissipated so far (J).
    pub fn dissipated_viscous(&self) -> Real {
        self.dissipated_viscous
    }

    /// Work done on the system by non-dynamic bodies and walls so far, with the work booked by
    /// [`super::World::record_external_work`] (J).
    pub fn external_work(&self) -> Real {
        self.external_work
    }
}

/// Every term of the ledger at one instant (J).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnergyReport {
    /// Simulated time (s).
    pub time: Real,
    /// Translational kinetic energy of the dynamic bodies (J).
    pub translational_kinetic: Real,
    /// Rotational kinetic energy of the dynamic bodies (J).
    pub rotational_kinetic: Real,
    /// Elastic energy stored in the contacts (normal and tangential) (J).
    pub elastic_potential: Real,
    /// Gravitational potential energy of the dynamic bodies (J).
    pub gravitational_potential: Real,
    /// Work of the normal damping dissipated so far (J).
    pub dissipated_damping: Real,
    /// Work of friction dissipated so far (J).
    pub dissipated_friction: Real,
    /// Work of the global viscous damping dissipated so far (J).
    pub dissipated_viscous: Real,
    /// Work done on the system by non-dynamic bodies and walls so far (J).
    pub external_work: Real,
    /// Work of the tangential stiffness change so far (J).
    pub tangential_stiffness_work: Real,
    /// E(t) + dissipated (+ removed by sleeping) − external − tangential stiffness work − E(0): zero for
    /// exact dynamics.
    pub balance: Real,
}

impl EnergyReport {
    /// Mechanical energy T + U (J).
    pub fn mechanical(&self) -> Real {
        self.translational_kinetic
            + self.rotational_kinetic
            + self.elastic_potential
            + self.gravitational_potential
    }

    /// The CSV header of [`EnergyReport::csv_row`].
    pub const CSV_HEADER: &'static str = "t,translational_kinetic,rotational_kinetic,elastic_potential,gravitational_potential,dissipated_damping,dissipated_friction,dissipated_viscous,external_work,tangential_stiffness_work,balance";

    /// One CSV row, full precision (shortest round-trip representation).
    pub fn csv_row(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{},{},{}",
            self.time,
            self.translational_kinetic,
            self.rotational_kinetic,
            self.elastic_potential,
            self.gravitational_potential,
            self.dissipated_damping,
            self.dissipated_friction,
            self.dissipated_viscous,
            self.external_work,
            self.tangential_stiffness_work,
            self.balance
        )
    }
}

/// The forces of a pair's last evaluation that the ledger needs: the damping part and the tangential
/// spring (u, its normal and k_t; the spring force was −k_t u).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LastForces {
    pub damping_force: Vector,
    pub history: TangentialHistory,
}

impl LastForces {
    /// No damping force and no stretched spring: nothing of the last evaluation to book.
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.damping_force == Vector::zeros()
            && (self.history.stiffness == 0.0 || self.history.displacement == Vector::zeros())
    }

    fn spring_force(&self) -> Vector {
        -self.history.stiffness * self.history.displacement
    }
}

/// The ledger terms one contact books for one step (J).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct ContactWork {
    /// Dissipated by the normal damping and the tangential dashpot.
    pub damping: Real,
    /// Dissipated by Coulomb slip.
    pub friction: Real,
    /// Work of the tangential stiffness change.
    pub stiffness: Real,
}

impl ContactWork {
    /// The terms of an overlapping contact whose last evaluation applied no force to book (a new
    /// contact): `relative_velocity` is v_B − v_A at the contact point with the half-step velocities.
    #[inline(always)]
    pub(crate) fn of_new_contact(
        response: &ContactResponse,
        relative_velocity: &Vector,
        dt: Real,
    ) -> Self {
        Self {
            damping: -0.5 * dt * response.damping_force.dot(relative_velocity),
            friction: response.friction_dissipation,
            stiffness: response.tangential_stiffness_work,
        }
    }

    /// The terms of an overlapping contact. `previous` holds the forces of the last evaluation and
    /// `previous_velocity` the relative velocity (half-step velocities) at the last contact point with
    /// the lever arms of the last step, with which those forces were applied; `response`, `normal` and
    /// `relative_velocity` are this evaluation's.
    ///
    /// Damping: −½ Δt (f_d^n·v_prev + f_d^(n+1)·v). Friction: the law's slip work, which measures the
    /// increment of the spring with this step's v (at the new contact point, in the new tangent plane),
    /// corrected by the difference between the work the last spring force did with the integrator's
    /// lever arms, ½ Δt f_s^n·v_prev, and the work the law's increment assumed, −½ k_t^n u_prev·v_t Δt.
    #[inline(always)]
    pub(crate) fn of_evaluation(
        previous: &LastForces,
        previous_velocity: &Vector,
        normal: &Vector,
        response: &ContactResponse,
        relative_velocity: &Vector,
        dt: Real,
    ) -> Self {
        let damping = -0.5
            * dt
            * (previous.damping_force.dot(previous_velocity)
                + response.damping_force.dot(relative_velocity));
        let h = &previous.history;
        let mut friction = response.friction_dissipation;
        if h.stiffness != 0.0 && h.displacement != Vector::zeros() {
            // The law rotated the same spring into the same plane (the same bits); a model without a
            // tangential law did not.
            let u_previous = response
                .previous_displacement
                .unwrap_or_else(|| rotate_into_tangent_plane(&h.displacement, &h.normal, normal));
            let v_t = relative_velocity - normal * relative_velocity.dot(normal);
            let assumed = -0.5 * dt * h.stiffness * u_previous.dot(&v_t);
            let applied = 0.5 * dt * previous.spring_force().dot(previous_velocity);
            friction -= applied - assumed;
        }
        Self {
            damping,
            friction,
            stiffness: response.tangential_stiffness_work,
        }
    }

    /// The terms of a contact that opened in this step (its last evaluation overlapped): the forces of
    /// that evaluation acted for the first half kick, with `relative_velocity` at the last contact point
    /// and the last lever arms; the spring is released ([`release_spring`], the law's k_t at zero
    /// overlap; `tangential` is the tangential slot of the pair's model).
    pub(crate) fn of_release(
        tangential: &TangentialLaw,
        previous: &LastForces,
        relative_velocity: &Vector,
        dt: Real,
    ) -> Self {
        let (end_stiffness, _) = tangential.stiffness_and_friction(0.0);
        let mut history = previous.history;
        let (friction, stiffness) =
            release_spring(end_stiffness, relative_velocity, dt, &mut history);
        Self {
            damping: -0.5 * dt * previous.damping_force.dot(relative_velocity),
            friction,
            stiffness,
        }
    }
}
