//! A cut by migration: after a rebuild, each rank sends each body it owns to the ranks that hold it next
//! (its new owner, the rank whose subdomain holds its centre, and the ranks whose ghost layer it lies in),
//! and each contact entry it answers for to the new owners of the entry's bodies (the ranks that evaluate
//! the pair). The subdomains stay those of the last bisection, so a rank exchanges with its neighbours
//! only and no rank holds the whole state. Each part holds the bodies a cut of the whole state with these
//! subdomains would give it and the entries of every pair it evaluates, so the bits stay one process's.

use mpi::traits::*;
use polydem::math::{Point, Real};
use polydem::world::{ContactKey, ContactState, PartBroadPhase, World};
use serde::{Deserialize, Serialize};

use crate::decomposition::{bisect, Region};
use crate::error::DistributedError;
use crate::exchange::{all_gather, exchange_with_near, pack_ghost, unpack_ghost, GHOST_WORDS};
use crate::plan::{ghost_width, Holding, MOVE_ALLOWANCE_IN_SKINS};
use crate::run::{DistributedRun, Part};

/// The most bodies new to a rank for which its part's list is carried over rather than built again: each
/// costs a test against every body of the part, a build about 3000 instructions per body.
const MAX_NEWCOMERS_CARRIED: usize = 128;

/// What one rank sends another at a migration.
#[derive(Clone, Default, Serialize, Deserialize)]
struct Migrants {
    /// Global indices of the bodies, increasing.
    ids: Vec<u32>,
    /// The owner of each body after the cut (found once, by the rank that owned it before).
    owners: Vec<u32>,
    /// Their states and loads, [`GHOST_WORDS`] numbers each.
    states: Vec<Real>,
    /// The contact entries (global keys) whose lower body is among `ids`.
    entries: Vec<(ContactKey, ContactState)>,
}

/// The gap (m) between two boxes (0 where they touch or overlap).
fn gap(a: &Region, b: &Region) -> Real {
    let mut sq = 0.0;
    for axis in 0..3 {
        let g = (a.min[axis] - b.max[axis])
            .max(b.min[axis] - a.max[axis])
            .max(0.0);
        sq += g * g;
    }
    sq.sqrt()
}

/// The ranks each body of a part goes to at a migration, body after body in one list (a vector per body
/// cost an allocation per body).
struct Destinations {
    /// Where each body's ranks start in `ranks` (one more entry than bodies).
    starts: Vec<u32>,
    ranks: Vec<u32>,
}

impl Destinations {
    fn with_bodies(count: usize) -> Self {
        Self {
            starts: Vec::with_capacity(count + 1),
            ranks: Vec::with_capacity(count),
        }
    }

    /// Opens the next body's ranks (and, after the last body, closes the list).
    fn next_body(&mut self) {
        self.starts.push(self.ranks.len() as u32);
    }

    /// Adds rank `q` to the open body's.
    fn add(&mut self, q: usize) {
        self.ranks.push(q as u32);
    }

    /// The ranks of body `i` (the open body's so far).
    fn of(&self, i: usize) -> &[u32] {
        let start = self.starts[i] as usize;
        let end = self
            .starts
            .get(i + 1)
            .map_or(self.ranks.len(), |&e| e as usize);
        &self.ranks[start..end]
    }
}

/// The owner after a cut of each body of a part: given for the bodies it owns (in local order), found
/// under the part's cuts for its ghosts when first asked (the rule every rank applies alike).
struct NewOwners {
    owner: Vec<NewOwner>,
}

#[derive(Clone, Copy, PartialEq)]
enum NewOwner {
    /// A ghost not asked about yet.
    Unknown,
    Rank(u32),
    /// A ghost whose centre is not finite (its owner refuses it).
    Nowhere,
}

impl NewOwners {
    fn new(part: &Part, owners: &[u32]) -> Self {
        let mut owner = vec![NewOwner::Unknown; part.ids.len()];
        let owned = (0..part.ids.len()).filter(|&i| part.owns(i));
        for (i, &o) in owned.zip(owners) {
            owner[i] = NewOwner::Rank(o);
        }
        Self { owner }
    }

    /// The new owner of local body `i` (`None` for a non-finite centre).
    fn of(&mut self, part: &Part, i: usize) -> Option<u32> {
        if self.owner[i] == NewOwner::Unknown {
            let x = &part.world.bodies()[i].position;
            self.owner[i] = match part.holding.cuts.owner_of(x, part.ids[i]) {
                Ok(q) => NewOwner::Rank(q as u32),
                Err(_) => NewOwner::Nowhere,
            };
        }
        match self.owner[i] {
            NewOwner::Rank(q) => Some(q),
            _ => None,
        }
    }
}

impl DistributedRun {
    /// Cuts new parts by migration within the present subdomains (after a rebuild and the check of the
    /// moves since the last cut). `largest_owned`: each rank's largest owned bounding radius after the cut
    /// (agreed by every rank); `owners`: the owner after the cut of each body this rank owns, in local
    /// order.
    pub(crate) fn migrate(
        &mut self,
        largest_owned: Vec<Real>,
        owners: Vec<u32>,
    ) -> Result<(), DistributedError> {
        self.part.holding.largest_owned = largest_owned;
        let near = self.near();
        self.migrate_to(&near, &owners)
    }

    /// Cuts new parts by a new bisection of the owned bodies' centres, gathered on every rank (after a
    /// rebuild, when the owned counts drifted apart): the bodies then migrate to the new subdomains as
    /// they do between neighbours, any rank to any rank.
    pub(crate) fn rebisect(&mut self) -> Result<(), DistributedError> {
        let part = &self.part;
        let owned = (0..part.ids.len()).filter(|&i| part.owns(i));
        let mine: Vec<(u32, [Real; 3])> = owned
            .map(|i| {
                let x = part.world.bodies()[i].position;
                (part.ids[i] as u32, [x.x, x.y, x.z])
            })
            .collect();
        let all = all_gather(&self.comm, &mine, &mut self.traffic.cuts)?;
        let mut centres = vec![Point::origin(); self.whole.body_count()];
        for (gid, x) in all.into_iter().flatten() {
            centres[gid as usize] = Point::new(x[0], x[1], x[2]);
        }
        let ranks = self.comm.size() as usize;
        let decomposition = bisect(&centres, ranks)?;
        let skin = self.whole.broad_phase().skin();
        self.part.holding = Holding::new(&decomposition, self.whole.radii(), skin);
        let owner = decomposition.owner;
        let part = &self.part;
        let owners: Vec<u32> = (0..part.ids.len())
            .filter(|&i| part.owns(i))
            .map(|i| owner[part.ids[i]])
            .collect();
        let everyone: Vec<usize> = (0..ranks).collect();
        self.migrate_to(&everyone, &owners)?;
        self.bisections += 1;
        Ok(())
    }

    /// Sends each owned body (with its new owner, of `owners` in local order) and the entries it answers
    /// for to the ranks of `near` that hold it under the part's holding rule, and assembles the new part
    /// from what arrives.
    fn migrate_to(&mut self, near: &[usize], owners: &[u32]) -> Result<(), DistributedError> {
        let mut outgoing = self.outgoing(near, owners)?;
        let mut mine = Some(std::mem::take(&mut outgoing[self.rank]));
        let blocks: Vec<Vec<u8>> = outgoing
            .iter()
            .map(|m| match m.ids.is_empty() {
                true => Vec::new(),
                false => postcard::to_allocvec(m).expect("encoding to memory does not fail"),
            })
            .collect();
        let received = exchange_with_near(&self.comm, near, &blocks, &mut self.traffic.cuts);
        let mut all = Vec::with_capacity(received.len());
        for (q, bytes) in received.iter().enumerate() {
            let migrants = match (q == self.rank, bytes.is_empty()) {
                (true, _) => mine.take().expect("this rank's own share is taken once"),
                (false, true) => Migrants::default(),
                (false, false) => {
                    postcard::from_bytes(bytes).map_err(|e| DistributedError::Decode {
                        rank: q,
                        message: e.to_string(),
                    })?
                }
            };
            all.push(migrants);
        }
        self.traffic.agreements += self.part.consensus.traffic();
        let ledger = *self.part.world.ledger();
        self.part = self.assemble(all, near);
        self.part.world.replace_ledger(ledger);
        self.whole_list_held = false;
        self.cuts += 1;
        Ok(())
    }

    /// The ranks that can hold a body this rank owns (itself included): those whose subdomain lies within
    /// the widest ghost layer plus twice the allowance of this one (a body owned here moved at most the
    /// allowance from this subdomain). The relation is symmetric, so each rank of a pair sends the other a
    /// message. The largest body is the largest any rank owns after the cut (O(P), not O(N)).
    fn near(&self) -> Vec<usize> {
        let holding = &self.part.holding;
        let regions = &holding.regions;
        let skin = self.whole.broad_phase().skin();
        let r_max = holding.largest_owned.iter().copied().fold(0.0, Real::max);
        let reach = ghost_width(r_max, skin) + 2.0 * MOVE_ALLOWANCE_IN_SKINS * skin;
        let within = |q: &usize| gap(&regions[*q], &regions[self.rank]) <= reach;
        (0..regions.len()).filter(within).collect()
    }

    /// What this rank sends each rank (its own entry included, not sent). A contact entry goes to the
    /// new owners of its bodies only, among the ranks its lower body goes to: a part evaluates the pairs
    /// of the bodies it owns ([`World::keep_pairs_of_owned`]), and its store drops any other entry at its
    /// next step.
    fn outgoing(&self, near: &[usize], owners: &[u32]) -> Result<Vec<Migrants>, DistributedError> {
        let (mut out, destinations) = self.outgoing_bodies(near, owners)?;
        let part = &self.part;
        let mut new_owner = NewOwners::new(part, owners);
        let store = part.world.contacts();
        let global = |i: u32| part.ids[i as usize] as u32;
        for (key, state) in store.keys().iter().zip(store.states()) {
            let (lower, upper, key) = match *key {
                ContactKey::Body { a, b } => (
                    a,
                    Some(b),
                    ContactKey::Body {
                        a: global(a),
                        b: global(b),
                    },
                ),
                ContactKey::Wall { body, wall } => (
                    body,
                    None,
                    ContactKey::Wall {
                        body: global(body),
                        wall,
                    },
                ),
            };
            let upper_owner = upper.and_then(|b| new_owner.of(part, b as usize));
            for &q in destinations.of(lower as usize) {
                if Some(q) == new_owner.of(part, lower as usize) || Some(q) == upper_owner {
                    out[q as usize].entries.push((key, *state));
                }
            }
        }
        Ok(out)
    }

    /// The bodies this rank sends each rank, and the ranks each of its bodies goes to.
    fn outgoing_bodies(
        &self,
        near: &[usize],
        owners: &[u32],
    ) -> Result<(Vec<Migrants>, Destinations), DistributedError> {
        let part = &self.part;
        let holding = &part.holding;
        let (bodies, loads) = (part.world.bodies(), part.world.loads());
        let mut out = vec![Migrants::default(); holding.regions.len()];
        let mut destinations = Destinations::with_bodies(part.ids.len());
        let mut owners = owners.iter();
        for (i, (&gid, body)) in part.ids.iter().zip(bodies).enumerate() {
            destinations.next_body();
            if !part.owns(i) {
                continue;
            }
            let owner = *owners.next().expect("one owner per owned body") as usize;
            let (x, r) = (&body.position, part.world.radii()[i]);
            for &q in near.iter().filter(|&&q| holding.holds(q, owner, x, r)) {
                let to = &mut out[q];
                to.ids.push(gid as u32);
                to.owners.push(owner as u32);
                let (force, torque) = (&loads.forces()[i], &loads.torques()[i]);
                pack_ghost(body, force, torque, &mut to.states);
                destinations.add(q);
            }
            if !destinations.of(i).contains(&(owner as u32)) {
                let allowance = MOVE_ALLOWANCE_IN_SKINS * self.whole.broad_phase().skin();
                return Err(DistributedError::HaloExceeded {
                    moved: holding.regions[self.rank].distance(x),
                    allowance,
                });
            }
        }
        destinations.next_body();
        Ok((out, destinations))
    }

    /// The new part `world` (of global bodies `ids`) with the list one process built in this step: the
    /// old part's, built at the same centres, carried over when few bodies are new to this rank (each is
    /// tested against every body), else built again.
    fn carry_list_over(&mut self, mut world: World, ids: &[usize]) -> World {
        let old = &self.part;
        let old_of_new: Vec<Option<u32>> = ids
            .iter()
            .map(|gid| old.ids.binary_search(gid).ok().map(|k| k as u32))
            .collect();
        let newcomers = old_of_new.iter().filter(|o| o.is_none()).count();
        let centres: Vec<Point> = world.bodies().iter().map(|b| b.position).collect();
        let rebuilds = old.world.broad_phase().rebuilds();
        if newcomers <= MAX_NEWCOMERS_CARRIED {
            let list = old.world.broad_phase();
            let list = list.carried_over(&old_of_new, &centres, world.radii(), world.walls());
            world.set_broad_phase(list);
            self.lists_carried += 1;
        } else {
            let walls = world.walls().to_vec();
            world.rebuild_broad_phase_at(&centres, &walls, rebuilds);
        }
        world
    }

    /// This rank's new part from what every rank sent it (in rank order); `near`: the ranks messages were
    /// exchanged with (every ghost's owner is among them, and every rank that holds a body owned here).
    fn assemble(&mut self, all: Vec<Migrants>, near: &[usize]) -> Part {
        let count = all.iter().map(|m| m.ids.len()).sum();
        let mut arrivals: Vec<(usize, u32, &[Real])> = Vec::with_capacity(count);
        for m in &all {
            let states = m.states.chunks_exact(GHOST_WORDS);
            let bodies = m.ids.iter().zip(&m.owners).zip(states);
            arrivals.extend(bodies.map(|((&gid, &owner), w)| (gid as usize, owner, w)));
        }
        // Each rank's bodies and entries come in increasing order: a stable sort merges the runs.
        arrivals.sort_by_key(|(gid, _, _)| *gid);
        // The whole world is the template of the part (shapes, materials, names); its bodies are written
        // only where this rank holds them.
        self.whole.copy_walls_and_clock(&self.part.world);
        for &(gid, _, w) in &arrivals {
            let (body, force, torque) = unpack_ghost(&self.whole.bodies()[gid], w);
            self.whole.copy_body_from_owner(gid, &body, &force, &torque);
        }
        let ids: Vec<usize> = arrivals.iter().map(|(gid, _, _)| *gid).collect();
        let owners: Vec<usize> = arrivals.iter().map(|(_, o, _)| *o as usize).collect();
        let mut entries = Vec::with_capacity(all.iter().map(|m| m.entries.len()).sum());
        for m in all {
            entries.extend(m.entries);
        }
        entries.sort_by_key(|entry| entry.0);
        let touched = self.part.world.contacts().last_touched();
        let world = self
            .whole
            .part_with_contacts(&ids, entries, touched, PartBroadPhase::Unbuilt);
        let holding = self.part.holding.clone();
        let positions: Vec<Point> = world.bodies().iter().map(|b| b.position).collect();
        let me = self.rank;
        let owned: Vec<bool> = owners.iter().map(|&o| o == me).collect();
        let mut world = self.carry_list_over(world, &ids);
        world.keep_pairs_of_owned(&owned);
        let ranks = holding.regions.len();
        let (mut sends, mut receives) = (vec![Vec::new(); ranks], vec![Vec::new(); ranks]);
        for i in 0..ids.len() {
            if !owned[i] {
                receives[owners[i]].push(i);
                continue;
            }
            let (x, r) = (&positions[i], world.radii()[i]);
            for &q in near.iter().filter(|&&q| q != me) {
                if holding.holds(q, me, x, r) {
                    sends[q].push(i);
                }
            }
        }
        let at_cut = (0..ids.len())
            .filter(|&i| owned[i])
            .map(|i| positions[i])
            .collect();
        Part::new(world, ids, owned, sends, receives, holding, at_cut)
    }
}
