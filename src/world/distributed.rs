//! Seams for a run split over several processes (the `polydem-mpi` crate): a world restricted to some of
//! the bodies, and state copied in from the process that owns it.
//!
//! A process steps a part of the world: the bodies it owns and copies (ghosts) of the bodies near them,
//! numbered in the order of their global index. The numbering keeps the order of every body's pairs, so an
//! owned body's forces are summed over the same pairs in the same order as in one process. The ghosts'
//! states and loads are overwritten from their owners after every step ([`World::copy_body_from_owner`]),
//! and the parts are cut again from the whole state after a broad-phase rebuild ([`World::part`]).

use crate::dynamics::RigidBody;
use crate::math::{Point, Vector};

use super::broad_phase::BroadPhase;
use super::contact_store::{ContactKey, ContactState, ContactStore};
use super::world::{Loads, World};

/// The broad phase a part of a world starts with ([`World::part`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PartBroadPhase {
    /// None: the next step builds it, as a fresh world's (the whole world's is not built either).
    Unbuilt,
    /// Built at the current positions and walls as the `rebuilds`-th build: a part cut right after the
    /// step that rebuilt the whole world's list (whose build positions are these).
    Build {
        /// The whole world's build count after that step.
        rebuilds: u64,
    },
    /// The whole world's list restricted to the part ([`BroadPhase::restricted`]): a part of a restored
    /// world, whose list was built at earlier positions.
    Restrict,
}

impl World {
    /// The world restricted to the bodies `ids` (strictly increasing), renumbered 0, 1, … in that order,
    /// with every shape, wall and material, the clock, the loads of the kept bodies and the contact entries
    /// whose bodies are all kept, and its broad phase as `broad_phase` says. The energy ledger starts
    /// empty and no body sleeps.
    pub fn part(&self, ids: &[usize], broad_phase: PartBroadPhase) -> World {
        debug_assert!(ids.windows(2).all(|w| w[0] < w[1]));
        let mut local = vec![u32::MAX; self.bodies.len()];
        for (k, &i) in ids.iter().enumerate() {
            local[i] = k as u32;
        }
        let pick = |v: &[Vector]| -> Vec<Vector> {
            if v.len() == self.bodies.len() {
                ids.iter().map(|&i| v[i]).collect()
            } else {
                Vec::new()
            }
        };
        let loads = Loads {
            forces: pick(&self.loads.forces),
            torques: pick(&self.loads.torques),
            ..self.loads.clone()
        };
        let entries = self.contacts.keys().iter().zip(self.contacts.states());
        let kept = entries.filter_map(|(key, state)| {
            let renumbered = match *key {
                ContactKey::Body { a, b } => {
                    let (a, b) = (local[a as usize], local[b as usize]);
                    (a != u32::MAX && b != u32::MAX).then_some(ContactKey::Body { a, b })
                }
                ContactKey::Wall { body, wall } => {
                    let body = local[body as usize];
                    (body != u32::MAX).then_some(ContactKey::Wall { body, wall })
                }
            };
            renumbered.map(|key| (key, *state))
        });
        let mut part = World::new(
            self.gravity,
            self.materials.clone(),
            self.broad_phase.skin(),
        );
        part.shapes = self.shapes.clone();
        part.bodies = ids.iter().map(|&i| self.bodies[i]).collect();
        part.shape_of = ids.iter().map(|&i| self.shape_of[i]).collect();
        part.material_of = ids.iter().map(|&i| self.material_of[i]).collect();
        part.radii = ids.iter().map(|&i| self.radii[i]).collect();
        part.names = ids.iter().map(|&i| self.names[i].clone()).collect();
        part.loads = loads;
        part.walls = self.walls.clone();
        part.time = self.time;
        part.step_index = self.step_index;
        part.replace_contacts(kept.collect(), self.contacts.last_touched());
        match broad_phase {
            PartBroadPhase::Unbuilt => {}
            PartBroadPhase::Build { rebuilds } => {
                let centres: Vec<Point> = part.bodies.iter().map(|b| b.position).collect();
                part.broad_phase
                    .rebuild_with_walls(&centres, &part.radii, &part.walls);
                part.broad_phase.set_rebuilds(rebuilds);
            }
            PartBroadPhase::Restrict => part.broad_phase = self.broad_phase.restricted(ids),
        }
        part
    }

    /// Body `i`'s state and loads copied from the process that owns it, bit for bit. Unlike the `set_body_*`
    /// edits the loads stay current: they are the owner's, evaluated at this state.
    pub fn copy_body_from_owner(
        &mut self,
        i: usize,
        body: &RigidBody,
        force: &Vector,
        torque: &Vector,
    ) {
        self.bodies[i] = *body;
        self.loads.forces[i] = *force;
        self.loads.torques[i] = *torque;
    }

    /// Replaces the contact store by `entries` (keys strictly increasing), touched last at step
    /// `last_touched`.
    pub fn replace_contacts(
        &mut self,
        entries: Vec<(ContactKey, ContactState)>,
        last_touched: u64,
    ) {
        let keys: Vec<ContactKey> = entries.iter().map(|(key, _)| *key).collect();
        let mut store = ContactStore::default();
        store.sync(&keys, last_touched);
        for (slot, (_, state)) in store.states_mut().iter_mut().zip(entries) {
            *slot = state;
        }
        self.contacts = store;
    }

    /// The walls, the clock and the loads other than the bodies' (wall forces, sums) of `other` (a part of
    /// this world stepped elsewhere) taken over, for a whole world reassembled from its parts; the sleeping
    /// state covers every body, as a step leaves it (no body sleeps in a split world).
    pub fn copy_walls_and_clock(&mut self, other: &World) {
        self.sleep.resize(self.bodies.len());
        self.walls = other.walls.clone();
        self.time = other.time;
        self.step_index = other.step_index;
        // The per-body loads stay (their owners write them); the rest is the part's.
        let mut forces = std::mem::take(&mut self.loads.forces);
        let mut torques = std::mem::take(&mut self.loads.torques);
        forces.resize(self.bodies.len(), Vector::zeros());
        torques.resize(self.bodies.len(), Vector::zeros());
        self.loads = Loads {
            forces,
            torques,
            ..other.loads.clone()
        };
    }

    /// The broad phase rebuilt at the current positions and walls, as the `rebuilds`-th build (a whole
    /// world reassembled from parts cut at its last build, whose list each part built for itself).
    pub fn rebuild_broad_phase_as(&mut self, rebuilds: u64) {
        let centres: Vec<Point> = self.bodies.iter().map(|b| b.position).collect();
        self.broad_phase
            .rebuild_with_walls(&centres, &self.radii, &self.walls);
        self.broad_phase.set_rebuilds(rebuilds);
    }

    /// The broad phase replaced by `broad_phase` (of the same bodies).
    pub fn set_broad_phase(&mut self, broad_phase: BroadPhase) {
        self.broad_phase = broad_phase;
    }

    /// The walls' contact forces of the last evaluation replaced by `wall_forces` (one per wall; summed
    /// elsewhere from the contact entries of a world split over processes).
    pub fn replace_wall_forces(&mut self, wall_forces: Vec<Vector>) {
        debug_assert_eq!(wall_forces.len(), self.walls.len());
        self.loads.wall_forces = wall_forces;
    }
}
