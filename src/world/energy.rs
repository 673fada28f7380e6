//! The energy ledger: where the energy of a run went, so that a run can be audited.
//!
//! At any state the mechanical energy is
//! E = T_trans + T_rot + U_elastic + U_gravity, with T summed over dynamic bodies (½ m|v|², ½ L̄·J̄⁻¹L̄),
//! U_elastic the sum of the contact laws' potentials (normal k_n δ^(n+1)/(n+1) and tangential ½ k_t |u|²) at
//! the current overlaps, and U_gravity = −Σ m g·x. The ledger accumulates, step by step:
//! - `dissipated_damping`: normal contact damping, Σ f_d δ̇ Δt (the damping power is evaluated with the
//!   half-step velocities, as the integrator docs explain, so this is a first-order quadrature);
//! - `dissipated_friction`: the Coulomb slip work the tangential law reports, μ F_n |Δu_slip|;
//! - `dissipated_viscous`: global viscous damping c|v|², trapezoidal over the step;
//! - `removed_by_sleeping`: the kinetic energy of bodies when they fell asleep (their velocities are then
//!   set to zero, see [`super::sleeping`]); part of the balance, not a column of [`EnergyReport`];
//! - `external_work`: the work done on the system by walls and non-dynamic bodies with a prescribed
//!   velocity, trapezoidal over the step (P = −F_on_wall·v_wall).
//!
//! The balance E(t) + dissipated − external − E(0) is zero for exact dynamics; for the discrete step it is the
//! integration error (second order for elastic contacts, bounded and oscillating for a symplectic run).

use crate::math::Real;
use crate::math::Vector;

use super::world::World;

/// Work accumulated since the start of the run (J).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnergyLedger {
    /// Mechanical energy at the first evaluation of the loads (J); `None` before it.
    pub initial_total: Option<Real>,
    pub dissipated_damping: Real,
    pub dissipated_friction: Real,
    pub dissipated_viscous: Real,
    pub external_work: Real,
    /// Kinetic energy removed when bodies fell asleep (J).
    #[serde(default)]
    pub removed_by_sleeping: Real,
}

/// Every term of the ledger at one instant (J).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnergyReport {
    pub time: Real,
    pub translational_kinetic: Real,
    pub rotational_kinetic: Real,
    pub elastic_potential: Real,
    pub gravitational_potential: Real,
    pub dissipated_damping: Real,
    pub dissipated_friction: Real,
    pub dissipated_viscous: Real,
    pub external_work: Real,
    /// E(t) + dissipated (+ removed by sleeping) − external − E(0): zero for exact dynamics.
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
    pub const CSV_HEADER: &'static str = "t,translational_kinetic,rotational_kinetic,elastic_potential,gravitational_potential,dissipated_damping,dissipated_friction,dissipated_viscous,external_work,balance";

    /// One CSV row, full precision (shortest round-trip representation).
    pub fn csv_row(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{},{}",
            self.time,
            self.translational_kinetic,
            self.rotational_kinetic,
            self.elastic_potential,
            self.gravitational_potential,
            self.dissipated_damping,
            self.dissipated_friction,
            self.dissipated_viscous,
            self.external_work,
            self.balance
        )
    }
}

/// Mechanical terms of the current state: (T_trans, T_rot, U_gravity) over dynamic bodies.
pub(crate) fn kinetic_and_gravity(world: &World) -> (Real, Real, Real) {
    let (mut trans, mut rot, mut grav) = (0.0, 0.0, 0.0);
    for body in world.bodies.iter().filter(|b| b.is_dynamic()) {
        trans += body.translational_kinetic_energy();
        rot += body.rotational_kinetic_energy();
        grav -= body.mass * world.gravity.dot(&body.position.coords);
    }
    (trans, rot, grav)
}

/// Σ c(m)|v|² over dynamic bodies (W): the power of a global viscous damping.
pub(crate) fn viscous_power(world: &World, coefficient: impl Fn(Real) -> Real) -> Real {
    world
        .bodies
        .iter()
        .filter(|b| b.is_dynamic())
        .map(|b| coefficient(b.mass) * b.velocity.norm_squared())
        .sum()
}

impl World {
    /// The ledger at the current state. Before the first step the elastic potential is that of the last
    /// load evaluation, i.e. zero until one ran.
    pub fn energy(&self) -> EnergyReport {
        let (translational_kinetic, rotational_kinetic, gravitational_potential) =
            kinetic_and_gravity(self);
        let l = &self.ledger;
        let mut report = EnergyReport {
            time: self.time,
            translational_kinetic,
            rotational_kinetic,
            elastic_potential: self.loads.elastic_potential,
            gravitational_potential,
            dissipated_damping: l.dissipated_damping,
            dissipated_friction: l.dissipated_friction,
            dissipated_viscous: l.dissipated_viscous,
            external_work: l.external_work,
            balance: 0.0,
        };
        let initial = l.initial_total.unwrap_or_else(|| report.mechanical());
        report.balance = report.mechanical()
            + l.dissipated_damping
            + l.dissipated_friction
            + l.dissipated_viscous
            + l.removed_by_sleeping
            - l.external_work
            - initial;
        report
    }

    /// Total linear momentum of the dynamic bodies (kg·m/s).
    pub fn linear_momentum(&self) -> Vector {
        self.bodies
            .iter()
            .filter(|b| b.is_dynamic())
            .map(|b| b.linear_momentum())
            .sum()
    }
}
