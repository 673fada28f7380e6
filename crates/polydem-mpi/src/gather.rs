//! The whole world's state gathered on rank 0 for outputs: every owned body's state and loads, the
//! touching body–wall entries (the walls' forces are summed from them on rank 0, in the order and with
//! the bits of one process's step), and, for an output that reads them (a checkpoint), the whole contact
//! store and broad phase as one process holds them.
//!
//! The contact entries come from the ranks that answer for them (a body pair from the owner of its lower
//! body, a body–wall pair from the body's owner), in key order. The whole broad phase is a function of the
//! centres, radii and walls at its last build, which are those of the last cut: rank 0 rebuilds it from
//! them when asked, with the build count the parts kept in step (a restored world's list is held as
//! restored until its first rebuild).

use polydem::math::Vector;
use polydem::world::broad_phase::BroadPhase;
use polydem::world::{ContactKey, ContactState, World};

use crate::error::DistributedError;
use crate::exchange::gather_to_root;
use crate::run::{authoritative_contacts, owned_bodies, DistributedRun};

impl DistributedRun {
    /// Collective: gathers the whole state on rank 0 and writes it into `world` there (the whole world
    /// this run was started from, or a copy of it; `None` on the other ranks): the bodies with their loads,
    /// the walls, the clock, and with `contacts` the contact store and the broad phase.
    pub fn gather_into(
        &mut self,
        world: Option<&mut World>,
        contacts: bool,
    ) -> Result<(), DistributedError> {
        let mut entries = authoritative_contacts(&self.part);
        if !contacts {
            entries
                .retain(|(key, state)| matches!(key, ContactKey::Wall { .. }) && state.is_active());
        }
        let mine = (owned_bodies(&self.part), entries);
        let traffic = &mut self.traffic;
        let all = gather_to_root(
            &self.comm,
            &mine,
            &mut traffic.gathers,
            &mut traffic.received_at_root,
        )?;
        let (Some(world), Some(all)) = (world, all) else {
            return Ok(());
        };
        world.copy_walls_and_clock(&self.part.world);
        let mut store = Vec::new();
        for (bodies, entries) in all {
            for (gid, body, force, torque) in bodies {
                world.copy_body_from_owner(gid, &body, &force, &torque);
            }
            store.extend(entries);
        }
        store.sort_by_key(|entry| entry.0);
        world.replace_wall_forces(wall_forces(&store, world.walls().len()));
        if contacts {
            let touched = self.part.world.contacts().last_touched();
            world.replace_contacts(store, touched);
            world.set_broad_phase(self.whole_list().clone());
        }
        Ok(())
    }

    /// The whole world's broad phase as one process holds it now.
    fn whole_list(&mut self) -> &BroadPhase {
        if !self.whole_list_held {
            let rebuilds = self.part.world.broad_phase().rebuilds();
            self.whole.rebuild_broad_phase_as(rebuilds);
            self.whole_list_held = true;
        }
        self.whole.broad_phase()
    }
}

/// The contact force on each of `walls` walls: the opposite of the force on the body of every touching
/// body–wall entry of `entries` (in key order), summed from zero in that order as the step sums them.
fn wall_forces(entries: &[(ContactKey, ContactState)], walls: usize) -> Vec<Vector> {
    let mut forces = vec![Vector::zeros(); walls];
    for (key, state) in entries {
        if let (ContactKey::Wall { wall, .. }, true) = (key, state.is_active()) {
            forces[*wall as usize] -= state.force_on_b;
        }
    }
    forces
}
