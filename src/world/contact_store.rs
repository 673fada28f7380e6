//! Per-contact state that must survive from one step to the next, keyed by the ordered pair.
//!
//! # Keys and order
//! A [`ContactKey`] is either a body pair `Body { a, b }` with `a < b`, or a body–wall pair
//! `Wall { body, wall }`. The derived order (all body pairs, sorted, then all wall pairs sorted by body then
//! wall) is the order of every later stage — narrow phase, laws and the accumulation of forces — so the
//! result does not depend on anything but the candidate list.
//!
//! # Orientation of a pair (which shape is A)
//! - Body pair: A is body `a` (the lower index), B is body `b`; the geometry's normal points from `a` to
//!   `b`, and the tangential displacement is that of `b` relative to `a`.
//! - Body–wall pair: A is the **wall**, B is the body; the normal is the wall's outward normal direction.
//!
//! The order never changes for a stored pair because indices do not change during a run. Whoever needs the
//! other order (a new pair convention, a renumbering) must convert a stored entry with
//! [`ContactState::swapped`]: the geometry goes through [`crate::contact::swap_pair`], the tangential
//! history through [`TangentialHistory::swapped`] (n and u change sign), and the GJK/EPA warm-start cache is
//! reset — it is expressed in A's frame with A's and B's vertex hints, and a cold start costs a few
//! iterations once, whereas a mis-oriented warm start would cost correctness checks. The tangential spring
//! is rotated into each new tangent plane by the law itself ([`crate::law::tangential::rotate_into_tangent_plane`])
//! from the normal stored with it, so the store only has to keep `TangentialHistory` intact.
//!
//! # Lifetime
//! [`ContactStore::sync`] merges the store (sorted by key) with the step's sorted candidate list: a
//! candidate with a stored entry keeps it, a new candidate gets a fresh one, and an entry whose pair left the
//! candidate list is dropped in the same pass. It is one linear merge, with no hashing, so the store is
//! plain sorted data that serialises and compares bit for bit.
//!
//! # Pairs of a body
//! `ContactStore::body_adjacency` lists, for every body, the store entries it takes part in, in key order
//! (compressed rows: [`BodyAdjacency`]). The step sums the forces on each body over its row — the same
//! additions in the same order as a scatter over the candidates, so the same bits — with the bodies in
//! parallel. The rows are derived from the keys only: built on first use after a sync that changed the
//! keys, kept while the keys stay (between broad-phase rebuilds), never serialised.

use crate::contact::{swap_pair, ContactGeometry, ContactKind, PairCache, SolverStatus};
use crate::law::TangentialHistory;
use crate::math::{Point, Vector};

pub use super::separation_bound::SeparationBound;

/// The ordered pair a contact belongs to (see the module docs for the orientation).
#[derive(
    Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum ContactKey {
    /// Two bodies, `a < b`; A = body a, B = body b.
    Body {
        /// Index of the body with the smaller index.
        a: u32,
        /// Index of the other body.
        b: u32,
    },
    /// A body and a wall; A = the wall, B = the body.
    Wall {
        /// Index of the body.
        body: u32,
        /// Index of the wall.
        wall: u32,
    },
}

/// What the store keeps for one pair.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactState {
    /// Warm start of GJK/EPA (in A's frame).
    pub cache: PairCache,
    /// The last proof that the pair was separated along `cache`'s axis, for the motion-bound skip (see
    /// [`super::skips`]; polyhedron pairs only, none otherwise).
    pub separation: SeparationBound,
    /// The tangential spring (B relative to A) and the normal it is expressed in.
    pub history: TangentialHistory,
    /// The step at which the pair entered the candidate list (the last step it was in the list is the
    /// store's [`ContactStore::last_touched`]: an entry that leaves the list is dropped).
    pub since_step: u64,
    /// The geometry of the last evaluation (A → B).
    pub geometry: ContactGeometry,
    /// The force on B of the last evaluation (N); A received its opposite.
    pub force_on_b: Vector,
    /// The velocity-dependent part of `force_on_b` (damping and tangential dashpot, N): the energy ledger
    /// books the damping work of a step from it and the next evaluation's (see [`super::energy`]).
    pub damping_force: Vector,
}

impl ContactState {
    /// A fresh entry for a pair entering the candidate list at `step`.
    pub fn new(step: u64) -> Self {
        Self {
            cache: PairCache::default(),
            separation: SeparationBound::default(),
            history: TangentialHistory::default(),
            since_step: step,
            geometry: ContactGeometry {
                kind: ContactKind::Separated,
                depth: 0.0,
                distance: 0.0,
                normal: Vector::zeros(),
                point_a: Point::origin(),
                point_b: Point::origin(),
                point: Point::origin(),
                status: SolverStatus::Exact,
            },
            force_on_b: Vector::zeros(),
            damping_force: Vector::zeros(),
        }
    }

    /// The same entry for the pair taken in the other order (B, A): see the module docs.
    pub fn swapped(&self) -> Self {
        Self {
            cache: PairCache::default(),
            separation: SeparationBound::default(),
            history: self.history.swapped(),
            geometry: swap_pair(&self.geometry),
            force_on_b: -self.force_on_b,
            damping_force: -self.damping_force,
            ..*self
        }
    }

    /// Whether the last evaluation found the shapes overlapping.
    pub fn is_active(&self) -> bool {
        self.geometry.kind == ContactKind::Overlap
    }
}

/// The contact store: entries sorted by key, aligned with the current candidate list after [`sync`].
///
/// [`sync`]: ContactStore::sync
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ContactStore {
    keys: Vec<ContactKey>,
    states: Vec<ContactState>,
    /// The step of the last sync: every entry was in the candidate list then.
    last_touched: u64,
    // Scratch for the merge, kept to avoid reallocating every step (not part of the state).
    #[serde(skip)]
    next_keys: Vec<ContactKey>,
    #[serde(skip)]
    next_states: Vec<ContactState>,
    /// The rows of [`body_adjacency`](Self::body_adjacency), derived from `keys` (not part of the state).
    #[serde(skip)]
    adjacency: BodyAdjacency,
    /// The tag of the candidate list of the last [`sync_tagged`](Self::sync_tagged) (0: none, or the keys
    /// changed otherwise since; not part of the state).
    #[serde(skip)]
    synced_tag: u64,
}

/// For every body, the store entries (= candidates after a sync) it takes part in, in key order: entry `k`
/// of body `i`'s row `entries[start[i]..start[i + 1]]` is an entry index, with [`BodyAdjacency::SIDE_A`]
/// set when the body is side A of a body pair (it receives the opposite of the force on B and the torque on
/// A); a body–wall pair lists the body as side B.
#[derive(Clone, Debug, Default)]
pub struct BodyAdjacency {
    /// Whether the rows match the store's keys (false after a sync that changed them).
    valid: bool,
    bodies: usize,
    /// Start of each body's row in `entries` (`bodies + 1` offsets).
    pub start: Vec<u32>,
    /// Entry indices, row after row, each possibly tagged with `SIDE_A`.
    pub entries: Vec<u32>,
}

impl BodyAdjacency {
    /// Flag of an entry in which the body is side A.
    pub const SIDE_A: u32 = 1 << 31;

    /// The row of body `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[u32] {
        &self.entries[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Builds the rows of `keys` for `bodies` bodies (every key's bodies must be below `bodies`).
    fn build(&mut self, keys: &[ContactKey], bodies: usize) {
        assert!(
            keys.len() < Self::SIDE_A as usize,
            "contact store: {} entries do not fit the adjacency's 31-bit indices",
            keys.len()
        );
        self.start.clear();
        self.start.resize(bodies + 1, 0);
        let sides = |key: &ContactKey| match *key {
            ContactKey::Body { a, b } => [Some(a), Some(b)],
            ContactKey::Wall { body, .. } => [None, Some(body)],
        };
        for key in keys {
            for body in sides(key).into_iter().flatten() {
                self.start[body as usize + 1] += 1;
            }
        }
        for i in 0..bodies {
            self.start[i + 1] += self.start[i];
        }
        self.entries.clear();
        self.entries.resize(self.start[bodies] as usize, 0);
        let mut fill = self.start.clone();
        for (k, key) in keys.iter().enumerate() {
            let [a, b] = sides(key);
            if let Some(a) = a {
                self.entries[fill[a as usize] as usize] = k as u32 | Self::SIDE_A;
                fill[a as usize] += 1;
            }
            if let Some(b) = b {
                self.entries[fill[b as usize] as usize] = k as u32;
                fill[b as usize] += 1;
            }
        }
        self.bodies = bodies;
        self.valid = true;
    }
}

/// Two stores are equal when they hold the same entries (the merge scratch does not count).
impl PartialEq for ContactStore {
    fn eq(&self, other: &Self) -> bool {
        self.keys == other.keys
            && self.states == other.states
            && self.last_touched == other.last_touched
    }
}

/// What [`ContactStore::sync`] did.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct SyncCounts {
    /// Entries whose key was already stored.
    pub kept: usize,
    /// Entries created for new candidates.
    pub created: usize,
    /// Entries dropped (no longer candidates).
    pub dropped: usize,
}

impl ContactStore {
    /// Makes the store hold exactly one entry per key of `candidates` (sorted, no duplicates), in that
    /// order: kept entries stay as they are, new ones are created, the others dropped; the store is marked
    /// touched at `step`.
    pub fn sync(&mut self, candidates: &[ContactKey], step: u64) -> SyncCounts {
        self.sync_tagged(candidates, 0, step)
    }

    /// [`sync`](Self::sync) with a tag that identifies the content of `candidates` (nonzero, and a list
    /// with another content never gets the same tag; 0: unknown): when the last sync had the same tag, the
    /// keys are the candidates already and the comparison of the two lists is skipped.
    pub(crate) fn sync_tagged(
        &mut self,
        candidates: &[ContactKey],
        tag: u64,
        step: u64,
    ) -> SyncCounts {
        debug_assert!(candidates.windows(2).all(|w| w[0] < w[1]));
        self.last_touched = step;
        if tag != 0 && tag == self.synced_tag {
            debug_assert!(candidates == self.keys.as_slice());
            return SyncCounts {
                kept: candidates.len(),
                ..SyncCounts::default()
            };
        }
        self.synced_tag = tag;
        if candidates == self.keys.as_slice() {
            // The same pairs as at the last sync (the usual case between broad-phase rebuilds): every entry
            // is kept in place.
            return SyncCounts {
                kept: candidates.len(),
                ..SyncCounts::default()
            };
        }
        self.next_keys.clear();
        self.next_states.clear();
        // A store made from entries (a part assembled at a migration) has no spare lists yet.
        self.next_keys.reserve(candidates.len());
        self.next_states.reserve(candidates.len());
        let mut counts = SyncCounts::default();
        let mut old = 0;
        for &key in candidates {
            while old < self.keys.len() && self.keys[old] < key {
                old += 1;
                counts.dropped += 1;
            }
            let state = if old < self.keys.len() && self.keys[old] == key {
                let kept = self.states[old];
                old += 1;
                counts.kept += 1;
                kept
            } else {
                counts.created += 1;
                ContactState::new(step)
            };
            self.next_keys.push(key);
            self.next_states.push(state);
        }
        counts.dropped += self.keys.len() - old;
        self.adjacency.valid = false;
        std::mem::swap(&mut self.keys, &mut self.next_keys);
        std::mem::swap(&mut self.states, &mut self.next_states);
        counts
    }

    /// A store of the entries `keys` (strictly increasing) with their `states`, synced last at step
    /// `last_touched`.
    pub fn from_entries(
        keys: Vec<ContactKey>,
        states: Vec<ContactState>,
        last_touched: u64,
    ) -> Self {
        debug_assert!(keys.windows(2).all(|w| w[0] < w[1]));
        debug_assert_eq!(keys.len(), states.len());
        Self {
            keys,
            states,
            last_touched,
            ..Self::default()
        }
    }

    /// The stored keys, sorted.
    pub fn keys(&self) -> &[ContactKey] {
        &self.keys
    }

    /// The state of each stored key, in key order.
    pub fn states(&self) -> &[ContactState] {
        &self.states
    }

    /// The states, mutable, in key order.
    pub(crate) fn states_mut(&mut self) -> &mut [ContactState] {
        &mut self.states
    }

    /// For every one of `bodies` bodies, the entries it takes part in, in key order (built here if the keys
    /// changed since the last call; see the module docs).
    pub(crate) fn body_adjacency(&mut self, bodies: usize) -> &BodyAdjacency {
        if !self.adjacency.valid || self.adjacency.bodies != bodies {
            self.adjacency.build(&self.keys, bodies);
        }
        &self.adjacency
    }

    /// The step of the last [`sync`](Self::sync): every entry was in the candidate list at that step.
    pub fn last_touched(&self) -> u64 {
        self.last_touched
    }

    /// The entry of `key`, if stored.
    pub fn get(&self, key: &ContactKey) -> Option<&ContactState> {
        self.keys.binary_search(key).ok().map(|i| &self.states[i])
    }

    /// Number of stored contacts.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// Whether no contact is stored.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sync_keeps_creates_and_drops_in_key_order() {
        let mut store = ContactStore::default();
        let k = |a, b| ContactKey::Body { a, b };
        store.sync(&[k(0, 1), k(0, 2), k(1, 2)], 0);
        store.states_mut()[0].history.displacement = Vector::new(1.0, 0.0, 0.0);
        let counts = store.sync(
            &[k(0, 1), k(1, 3), ContactKey::Wall { body: 0, wall: 0 }],
            5,
        );
        assert_eq!(
            counts,
            SyncCounts {
                kept: 1,
                created: 2,
                dropped: 2
            }
        );
        assert_eq!(
            store.keys(),
            &[k(0, 1), k(1, 3), ContactKey::Wall { body: 0, wall: 0 }]
        );
        let kept = store.get(&k(0, 1)).expect("kept entry");
        assert_eq!(kept.history.displacement, Vector::new(1.0, 0.0, 0.0));
        assert_eq!((kept.since_step, store.last_touched()), (0, 5));
        assert_eq!(store.get(&k(1, 3)).expect("new entry").since_step, 5);
        assert!(store.get(&k(0, 2)).is_none());
    }

    #[test]
    fn adjacency_lists_each_body_s_entries_in_key_order_and_follows_syncs() {
        let mut store = ContactStore::default();
        let k = |a, b| ContactKey::Body { a, b };
        let w = |body, wall| ContactKey::Wall { body, wall };
        store.sync(&[k(0, 1), k(0, 2), k(1, 2), w(1, 0), w(2, 1)], 0);
        let side_a = BodyAdjacency::SIDE_A;
        let rows = |s: &mut ContactStore, n| {
            let adj = s.body_adjacency(n);
            (0..n).map(|i| adj.row(i).to_vec()).collect::<Vec<_>>()
        };
        assert_eq!(
            rows(&mut store, 4),
            vec![
                vec![side_a, 1 | side_a],
                vec![0, 2 | side_a, 3],
                vec![1, 2, 4],
                vec![]
            ]
        );
        // A sync that changes the keys rebuilds the rows; one that keeps them keeps them.
        store.sync(&[k(1, 3), w(0, 0)], 1);
        assert_eq!(
            rows(&mut store, 4),
            vec![vec![1], vec![side_a], vec![], vec![0]]
        );
        store.sync(&[k(1, 3), w(0, 0)], 2);
        assert_eq!(
            rows(&mut store, 4),
            vec![vec![1], vec![side_a], vec![], vec![0]]
        );
    }

    #[test]
    fn swapping_twice_restores_history_and_geometry() {
        let mut s = ContactState::new(3);
        s.history.displacement = Vector::new(0.0, 1e-4, 0.0);
        s.history.normal = Vector::z();
        s.geometry.normal = Vector::z();
        s.geometry.point_a = Point::new(0.0, 0.0, 1.0);
        s.force_on_b = Vector::new(0.0, 0.0, 2.0);
        let back = s.swapped().swapped();
        assert_eq!(back.history, s.history);
        assert_eq!(back.geometry, s.geometry);
        assert_eq!(back.force_on_b, s.force_on_b);
        assert_eq!(s.swapped().history.normal, -Vector::z());
    }
}
