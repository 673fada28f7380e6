//! The whole world's state gathered on rank 0 for outputs: every owned body's state and loads (19 numbers,
//! as in the ghost exchange), the touching body–wall entries (the walls' forces are summed from them on
//! rank 0, in the order and with the bits of one process's step), and, for an output that reads them (a
//! checkpoint), the whole contact store and broad phase as one process holds them.
//!
//! The contact entries come from the ranks that answer for them (a body pair from the owner of its lower
//! body, a body–wall pair from the body's owner), in key order. The whole broad phase is a function of the
//! centres, radii and walls at its last build, which are those of the last cut: the owners send their
//! bodies' positions at the cut with the first such gather after it, and rank 0 rebuilds the list from
//! them and the walls at the cut, with the build count the parts kept in step (a restored world's list is
//! held as restored until its first rebuild).

use polydem::math::{Point, Real};
use polydem::world::{EnergyShare, World};

use crate::error::DistributedError;
use crate::exchange::{gather_to_root, pack_ghost, unpack_ghost, GHOST_WORDS};
use crate::run::{authoritative_contacts, DistributedRun, Part};
use crate::wall_sums::{touching_walls, wall_forces};

impl DistributedRun {
    /// Collective: gathers the whole state on rank 0 and writes it into `world` there (the whole world
    /// this run was started from, or a copy of it; `None` on the other ranks): the bodies with their loads,
    /// the walls, the clock, and with `contacts` the contact store and the broad phase.
    pub fn gather_into(
        &mut self,
        world: Option<&mut World>,
        contacts: bool,
    ) -> Result<(), DistributedError> {
        if self.fresh {
            // `world` is still the state the run started from.
            return Ok(());
        }
        let entries = authoritative_contacts(&self.part);
        let touching_walls = touching_walls(&entries);
        let entries = if contacts { entries } else { Vec::new() };
        let (ids, states) = owned_states(&self.part);
        let share = self.part.world.energy_share();
        // The whole list is rebuilt on rank 0 from the positions of the last cut (once per cut).
        let rebuild_list = contacts && !self.whole_list_held;
        let at_cut: Vec<Real> = match rebuild_list {
            true => self
                .part
                .at_cut
                .iter()
                .flat_map(|x| x.coords.iter().copied())
                .collect(),
            false => Vec::new(),
        };
        self.whole_list_held |= contacts;
        let mine = (ids, states, touching_walls, entries, share, at_cut);
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
        let (mut store, mut walls) = (Vec::new(), Vec::new());
        let mut total = EnergyShare::default();
        let mut centres = vec![Point::origin(); world.body_count()];
        for (ids, states, touching_walls, entries, share, at_cut) in all {
            total.add(&share);
            for (&gid, w) in ids.iter().zip(states.chunks_exact(GHOST_WORDS)) {
                let (body, force, torque) = unpack_ghost(&world.bodies()[gid as usize], w);
                world.copy_body_from_owner(gid as usize, &body, &force, &torque);
            }
            for (&gid, x) in ids.iter().zip(at_cut.chunks_exact(3)) {
                centres[gid as usize] = Point::new(x[0], x[1], x[2]);
            }
            walls.extend(touching_walls);
            store.extend(entries);
        }
        walls.sort_by_key(|entry| entry.0);
        world.replace_wall_forces(wall_forces(&walls, world.walls().len()));
        world.replace_energy_share(&total);
        if contacts {
            store.sort_by_key(|entry| entry.0);
            let touched = self.part.world.contacts().last_touched();
            world.replace_contacts(store, touched);
            if rebuild_list {
                let rebuilds = self.part.world.broad_phase().rebuilds();
                let walls = &self.part.walls_at_cut;
                self.whole.rebuild_broad_phase_at(&centres, walls, rebuilds);
            }
            world.set_broad_phase(self.whole.broad_phase().clone());
        }
        Ok(())
    }
}

/// The global indices of the bodies `part` owns and their states and loads, packed as the ghost exchange
/// packs them (the mass properties and motion, which do not change, stay behind).
fn owned_states(part: &Part) -> (Vec<u32>, Vec<Real>) {
    let (bodies, loads) = (part.world.bodies(), part.world.loads());
    let owned: Vec<usize> = (0..part.ids.len()).filter(|&i| part.owns(i)).collect();
    let mut states = Vec::with_capacity(owned.len() * GHOST_WORDS);
    for &i in &owned {
        pack_ghost(
            &bodies[i],
            &loads.forces()[i],
            &loads.torques()[i],
            &mut states,
        );
    }
    let ids = owned.iter().map(|&i| part.ids[i] as u32).collect();
    (ids, states)
}
