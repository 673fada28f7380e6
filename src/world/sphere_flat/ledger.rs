//! The per-contact terms of the energy ledger on the flat sphere path.
//!
//! The general step books, per candidate and step, the damping work of the last and the new damping
//! force, the friction (slip) work and the tangential stiffness work ([`ContactWork`], see
//! [`crate::world::energy`]), and sums them serially in candidate order. The flat path does the same with
//! the same functions: per listed pair it keeps the last evaluation's damping force and contact point
//! ([`LastContact`]; the spring is the list's), and the terms are summed in pair order — body pairs by
//! (a, b), then body–wall pairs by (body, wall): the general step's candidate order. A serial pair loop
//! (one block) visits the pairs in that order and sums them as it goes; a pair loop in blocks writes
//! each evaluated pair's terms into the pair's own slot ([`super::pair`]), and stage 9 sums the slots
//! serially, resetting each for the next step ([`PairLedger::take_sums`]). A pair the pair loop skips
//! (apart, and apart at the last evaluation) books nothing on either path, and a zero added to a sum
//! that starts at +0 leaves it unchanged, so the sums are the same bits as the general step's, for any
//! number of threads.
//!
//! The last forces follow a pair across a rebuild of the lists ([`PairLedger::carry`]) and are imported
//! from the world's contact store on the first build, as the springs are. A pair with a damping force
//! to book is marked in contact after a build (the pair loop then evaluates it, and books its release if
//! it opened), as a pair with a held spring is.

use crate::math::{Point, Vector};

use super::super::contact_store::{ContactKey, ContactStore};
use super::super::energy::ContactWork;
use super::neighbours::{NeighbourList, NOT_CARRIED};

/// What the ledger keeps of a pair's last evaluation besides its spring: the velocity-dependent part of
/// the force on B (N) and the contact point (world, m) the forces were applied at. Zero for a pair that
/// did not overlap.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct LastContact {
    pub(crate) damping_force: Vector,
    pub(crate) point: Point,
}

/// Per listed pair, aligned with the lists: the last contact and this step's ledger terms (empty when
/// the ledger is off).
#[derive(Clone, Debug, Default)]
pub(crate) struct PairLedger {
    pub(crate) last: Vec<LastContact>,
    pub(crate) work: Vec<ContactWork>,
    pub(crate) wall_last: Vec<LastContact>,
    pub(crate) wall_work: Vec<ContactWork>,
    /// The sums of the last evaluation when its pair loop took them in pair order itself (one block),
    /// leaving the slots zero.
    pub(crate) summed: Option<ContactWork>,
}

/// The wall rows of the lists before a build, to find a wall pair's slot of the build before (the lists
/// carry no index for wall pairs).
pub(crate) struct OldWalls {
    wall_start: Vec<u32>,
    wall_of: Vec<u32>,
}

impl OldWalls {
    pub(crate) fn of(list: &NeighbourList) -> Self {
        Self {
            wall_start: list.wall_start.clone(),
            wall_of: list.wall_of.clone(),
        }
    }

    /// The slot of the pair (body, wall) in the lists before, if it was listed.
    fn slot(&self, body: usize, wall: u32) -> Option<usize> {
        let (s, e) = match self.wall_start.get(body..body + 2) {
            Some(&[s, e]) => (s as usize, e as usize),
            _ => return None,
        };
        self.wall_of[s..e]
            .iter()
            .position(|&w| w == wall)
            .map(|k| s + k)
    }
}

impl PairLedger {
    /// The ledger of the lists `list` just built: each pair's last contact carried from the lists before
    /// (`old_walls` their wall rows), else taken from `store` (the world's contact store, on the first
    /// build), else zero; the terms zero. Marks in contact every pair with a damping force to book.
    pub(crate) fn carry(
        &mut self,
        list: &mut NeighbourList,
        old_walls: Option<&OldWalls>,
        store: Option<&ContactStore>,
    ) {
        let imported = |key: ContactKey| {
            store
                .and_then(|s| s.get(&key))
                .map(|s| LastContact {
                    damping_force: s.damping_force,
                    point: s.geometry.point,
                })
                .unwrap_or_default()
        };
        let old_last = std::mem::take(&mut self.last);
        self.last = (0..list.a.len())
            .map(|p| match list.carried_from[p] {
                NOT_CARRIED => imported(ContactKey::Body {
                    a: list.a[p],
                    b: list.b[p],
                }),
                from => old_last.get(from as usize).copied().unwrap_or_default(),
            })
            .collect();
        let old_wall_last = std::mem::take(&mut self.wall_last);
        self.wall_last = list
            .wall_body
            .iter()
            .zip(&list.wall_of)
            .map(
                |(&body, &wall)| match old_walls.and_then(|old| old.slot(body as usize, wall)) {
                    Some(k) => old_wall_last.get(k).copied().unwrap_or_default(),
                    None => imported(ContactKey::Wall { body, wall }),
                },
            )
            .collect();
        self.work.clear();
        self.work.resize(self.last.len(), ContactWork::default());
        self.wall_work.clear();
        self.wall_work
            .resize(self.wall_last.len(), ContactWork::default());
        let pending = |l: &LastContact| l.damping_force != Vector::zeros();
        for (flag, l) in list.in_contact.iter_mut().zip(&self.last) {
            *flag |= pending(l);
        }
        for (flag, l) in list.wall_in_contact.iter_mut().zip(&self.wall_last) {
            *flag |= pending(l);
        }
    }

    /// The sums of the step's terms in pair order (body pairs, then body–wall pairs; each term its own
    /// sum from +0, as the general step's stage 6), every slot reset to zero for the next step.
    pub(crate) fn take_sums(&mut self) -> ContactWork {
        if let Some(sum) = self.summed.take() {
            return sum;
        }
        let mut sum = ContactWork::default();
        for w in self.work.iter_mut().chain(self.wall_work.iter_mut()) {
            let w = std::mem::take(w);
            sum.damping += w.damping;
            sum.friction += w.friction;
            sum.stiffness += w.stiffness;
        }
        sum
    }
}
