//! The loads of the last force evaluation: the resultant contact force and torque on each body and wall,
//! and the sums the energy ledger takes from that evaluation.
//!
//! The step writes them; everything else reads them through the methods below, so that the flag telling
//! whether they belong to the current positions ([`Loads::is_current`]) is only cleared by the edits that
//! move a body or a wall (see [`super::World`]'s edit methods).

use crate::math::{Real, Vector};

/// Resultant force and torque on each body from the last contact evaluation, and the sums the energy
/// ledger needs from it. The step evaluates forces once, at the new positions, and reuses them for the
/// next step's first half kick.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Loads {
    /// Contact force on each body (N), world frame (gravity is added by the integrator).
    pub(in crate::world) forces: Vec<Vector>,
    /// Contact torque about each body's centre of mass (N·m), world frame.
    pub(in crate::world) torques: Vec<Vector>,
    /// Total contact force on each wall (N).
    pub(in crate::world) wall_forces: Vec<Vector>,
    /// Σ of the elastic potentials (normal power law and tangential spring) of all contacts (J).
    pub(in crate::world) elastic_potential: Real,
    /// Σ of the damping work dissipated during the step that produced these loads (J; see
    /// [`super::energy`]).
    pub(in crate::world) damping_work: Real,
    /// Σ of the friction work dissipated during the step that produced these loads (J).
    pub(in crate::world) friction_dissipation: Real,
    /// Σ of the work of the tangential stiffness change during the step that produced these loads (J).
    pub(in crate::world) tangential_stiffness_work: Real,
    /// Power (W) the non-dynamic bodies and the walls deliver to the system through contacts.
    pub(in crate::world) external_power: Real,
    /// Whether these loads belong to the current state (false before the first evaluation).
    pub(in crate::world) current: bool,
}

impl Loads {
    /// Contact force on each body (N, world frame, gravity not included), in body order; empty before
    /// the first evaluation.
    pub fn forces(&self) -> &[Vector] {
        &self.forces
    }

    /// Contact torque on each body about its centre of mass (N·m, world frame), in body order.
    pub fn torques(&self) -> &[Vector] {
        &self.torques
    }

    /// Total contact force on each wall (N, world frame), in wall order.
    pub fn wall_forces(&self) -> &[Vector] {
        &self.wall_forces
    }

    /// Elastic energy stored in the contacts at this evaluation (J).
    pub fn elastic_potential(&self) -> Real {
        self.elastic_potential
    }

    /// Damping work dissipated during the step that produced these loads (J).
    pub fn damping_work(&self) -> Real {
        self.damping_work
    }

    /// Friction work dissipated during the step that produced these loads (J).
    pub fn friction_dissipation(&self) -> Real {
        self.friction_dissipation
    }

    /// Work of the tangential stiffness change during the step that produced these loads (J).
    pub fn tangential_stiffness_work(&self) -> Real {
        self.tangential_stiffness_work
    }

    /// Power (W) the non-dynamic bodies and the walls deliver through contacts at this evaluation.
    pub fn external_power(&self) -> Real {
        self.external_power
    }

    /// Whether these loads were evaluated at the current positions (false before the first evaluation
    /// and after an edit that moved a body or a wall).
    pub fn is_current(&self) -> bool {
        self.current
    }
}
