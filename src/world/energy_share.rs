//! A part's share of the energy sums, for a world split over processes ([`super::distributed`]).
//!
//! Every energy sum is additive over bodies and pairs: the kinetic and gravitational terms over bodies,
//! the elastic potential and the contact work terms over pairs, the external power over walls' pairs and
//! prescribed bodies, the viscous power over bodies. A part counts the bodies it owns and the pairs it
//! answers for (a body pair where it owns the lower body, a body–wall pair where it owns the body), marked
//! by [`World::count_only`]; its ghosts' pairs with each other, evaluated too, are left to their owners.
//! Each term is then counted on exactly one part, and the whole world's ledger is the sum of the parts'
//! [`EnergyShare`]s. Not bitwise one process's: the sum is grouped by part, so it differs from one
//! process's in rounding.

use crate::math::{Real, Vector};

use super::contact_store::ContactKey;
use super::energy::EnergyLedger;
use super::world::World;

/// What a part counts of the energy: its ledger (the terms booked on its steps) and the sums of its last
/// evaluation. The whole world's are the sums of the parts' ([`EnergyShare::add`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnergyShare {
    ledger: EnergyLedger,
    elastic_potential: Real,
    damping_work: Real,
    friction_dissipation: Real,
    tangential_stiffness_work: Real,
    external_power: Real,
}

impl EnergyShare {
    /// `other` added term by term. The initial mechanical energy is the sum of those the parts have (a
    /// part restored from a checkpoint starts without one: rank 0's carries the whole world's).
    pub fn add(&mut self, other: &EnergyShare) {
        let (l, o) = (&mut self.ledger, &other.ledger);
        l.initial_total = match (l.initial_total, o.initial_total) {
            (Some(a), Some(b)) => Some(a + b),
            (a, b) => a.or(b),
        };
        l.dissipated_damping += o.dissipated_damping;
        l.dissipated_friction += o.dissipated_friction;
        l.dissipated_viscous += o.dissipated_viscous;
        l.external_work += o.external_work;
        l.removed_by_sleeping += o.removed_by_sleeping;
        l.tangential_stiffness_work += o.tangential_stiffness_work;
        self.elastic_potential += other.elastic_potential;
        self.damping_work += other.damping_work;
        self.friction_dissipation += other.friction_dissipation;
        self.tangential_stiffness_work += other.tangential_stiffness_work;
        self.external_power += other.external_power;
    }
}

impl World {
    /// Marks this world as a part of a split world owning the bodies where `owned` is true (one flag per
    /// body): from now on its energy sums count only those bodies and the pairs it answers for (module
    /// docs). With current loads, the walls' forces of the last evaluation are recounted over those pairs
    /// from the contact store, so that the next step's external power is this part's share too (stale
    /// loads are evaluated afresh by the next step).
    ///
    /// The mark is for a part's whole life: the body set must not change afterwards (the flags are
    /// indexed by body), and sleeping must stay off (the frozen contacts of sleeping bodies are summed
    /// once for all of them, not split by owner; a split run refuses sleeping).
    pub fn count_only(&mut self, owned: Vec<bool>) {
        assert_eq!(owned.len(), self.bodies.len(), "one flag per body");
        if self.loads.current && self.loads.wall_forces.len() == self.walls.len() {
            let mut wall_forces = vec![Vector::zeros(); self.walls.len()];
            let entries = self.contacts.keys().iter().zip(self.contacts.states());
            for (key, state) in entries.filter(|(_, state)| state.is_active()) {
                if let ContactKey::Wall { body, wall } = *key {
                    if owned[body as usize] {
                        wall_forces[wall as usize] -= state.force_on_b;
                    }
                }
            }
            self.loads.wall_forces = wall_forces;
        }
        self.counted = Some(owned);
    }

    /// Whether this world's energy sums count body `i` (every body, unless [`World::count_only`] said).
    #[inline]
    pub fn counts_body(&self, i: usize) -> bool {
        self.counted.as_ref().is_none_or(|owned| owned[i])
    }

    /// This world's share of the energy sums: the whole world's unless [`World::count_only`] marked it as
    /// a part.
    pub fn energy_share(&self) -> EnergyShare {
        let loads = &self.loads;
        EnergyShare {
            ledger: self.ledger,
            elastic_potential: loads.elastic_potential,
            damping_work: loads.damping_work,
            friction_dissipation: loads.friction_dissipation,
            tangential_stiffness_work: loads.tangential_stiffness_work,
            external_power: loads.external_power,
        }
    }

    /// The ledger and the energy sums of the last evaluation replaced by `share` (a whole world
    /// reassembled from its parts: the sum of their shares).
    pub fn replace_energy_share(&mut self, share: &EnergyShare) {
        self.ledger = share.ledger;
        let loads = &mut self.loads;
        loads.elastic_potential = share.elastic_potential;
        loads.damping_work = share.damping_work;
        loads.friction_dissipation = share.friction_dissipation;
        loads.tangential_stiffness_work = share.tangential_stiffness_work;
        loads.external_power = share.external_power;
    }

    /// The energy ledger replaced by `ledger` (a part carrying its share over a new cut).
    pub fn replace_ledger(&mut self, ledger: EnergyLedger) {
        self.ledger = ledger;
    }
}
