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
use super::world::{Loads, Wall, World};

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
        let entries = self.contacts.keys().iter().zip(self.contacts.states());
        let entries = entries.map(|(key, state)| (*key, *state));
        self.part_with_contacts(ids, entries, self.contacts.last_touched(), broad_phase)
    }

    /// As [`World::part`], with the contact entries `entries` (keyed in this world's numbering, in
    /// increasing key order; those with a body not kept are dropped) in place of this world's store, touched
    /// last at step `last_touched`: a part assembled from entries that other processes sent.
    pub fn part_with_contacts(
        &self,
        ids: &[usize],
        entries: impl IntoIterator<Item = (ContactKey, ContactState)>,
        last_touched: u64,
        broad_phase: PartBroadPhase,
    ) -> World {
        debug_assert!(ids.windows(2).all(|w| w[0] < w[1]));
        let local = |i: u32| ids.binary_search(&(i as usize)).ok().map(|k| k as u32);
        let renumbered = |key| match key {
            ContactKey::Body { a, b } => Some(ContactKey::Body {
                a: local(a)?,
                b: local(b)?,
            }),
            ContactKey::Wall { body, wall } => Some(ContactKey::Wall {
                body: local(body)?,
                wall,
            }),
        };
        let entries = entries.into_iter();
        let (mut keys, mut states) = (
            Vec::with_capacity(entries.size_hint().0),
            Vec::with_capacity(entries.size_hint().0),
        );
        for (key, state) in entries {
            if let Some(key) = renumbered(key) {
                keys.push(key);
                states.push(state);
            }
        }
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
        part.loads = self.loads_of(ids);
        part.walls = self.walls.clone();
        part.time = self.time;
        part.step_index = self.step_index;
        part.contacts = ContactStore::from_entries(keys, states, last_touched);
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

    /// The loads with the per-body forces and torques of `ids` only (none where none are evaluated).
    fn loads_of(&self, ids: &[usize]) -> Loads {
        let pick = |v: &[Vector]| -> Vec<Vector> {
            if v.len() == self.bodies.len() {
                ids.iter().map(|&i| v[i]).collect()
            } else {
                Vec::new()
            }
        };
        let l = &self.loads;
        Loads {
            forces: pick(&l.forces),
            torques: pick(&l.torques),
            wall_forces: l.wall_forces.clone(),
            elastic_potential: l.elastic_potential,
            damping_work: l.damping_work,
            friction_dissipation: l.friction_dissipation,
            tangential_stiffness_work: l.tangential_stiffness_work,
            external_power: l.external_power,
            current: l.current,
        }
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
        let (keys, states) = entries.into_iter().unzip();
        self.contacts = ContactStore::from_entries(keys, states, last_touched);
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

    /// The broad phase rebuilt at `centres` (one per body) and `walls`, as the `rebuilds`-th build (a whole
    /// world reassembled from parts cut at its last build, whose list each part built for itself at those
    /// centres and walls).
    pub fn rebuild_broad_phase_at(&mut self, centres: &[Point], walls: &[Wall], rebuilds: u64) {
        debug_assert_eq!(centres.len(), self.bodies.len());
        self.broad_phase
            .rebuild_with_walls(centres, &self.radii, walls);
        self.broad_phase.set_rebuilds(rebuilds);
    }

    /// The broad phase without the pairs of two bodies not `owned` here, nor the wall pairs of such a
    /// body: a part of a world split over processes need not evaluate them, since the bodies' states and
    /// loads are overwritten by their owners' after each step ([`BroadPhase::keep_pairs_of`]).
    pub fn keep_pairs_of_owned(&mut self, owned: &[bool]) {
        debug_assert_eq!(owned.len(), self.bodies.len());
        self.broad_phase.keep_pairs_of(|i| owned[i as usize]);
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
