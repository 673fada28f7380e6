//! The broad-phase rebuild decision of the whole world, taken by every part.
//!
//! One process rebuilds when a wall or the body count forces it, or when some body moved half the skin and
//! the two largest body moves (with the walls') may have brought a pair within reach. The two largest moves
//! of the whole world are the two largest of the ranks' owned pairs (each body counted once, where it is
//! owned), so one all-gather of four numbers per rank gives every part the same decision as one process.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use polydem::math::Real;
use polydem::world::{RebuildConsensus, RebuildVote};

use crate::exchange::Traffic;

/// The decision of one part, agreed with the other ranks at every stage 3.
#[derive(Debug)]
pub struct Consensus {
    /// Whether each body of the part is owned here.
    owned: Vec<bool>,
    /// The decision of the last call (whether the last stage 3 rebuilt).
    last: AtomicBool,
    /// Bytes this rank sent in the agreements (to each other rank).
    bytes: AtomicU64,
    /// Messages this rank sent in the agreements (one to each other rank per agreement).
    messages: AtomicU64,
}

impl Consensus {
    /// The consensus of a part whose bodies are `owned` here or not.
    pub fn new(owned: Vec<bool>) -> Self {
        Self {
            owned,
            last: AtomicBool::new(false),
            bytes: AtomicU64::new(0),
            messages: AtomicU64::new(0),
        }
    }

    /// What this rank sent in the agreements so far.
    pub fn traffic(&self) -> Traffic {
        Traffic {
            bytes: self.bytes.load(Ordering::Relaxed),
            messages: self.messages.load(Ordering::Relaxed),
        }
    }

    /// Whether the last stage 3 rebuilt the broad phase.
    pub fn last_rebuilt(&self) -> bool {
        self.last.load(Ordering::Relaxed)
    }
}

impl RebuildConsensus for Consensus {
    fn decide(&self, vote: &RebuildVote<'_>) -> bool {
        let owned = |i: usize| self.owned[i];
        let (d1, d2) = vote.broad_phase.largest_moves_sq(vote.centres, owned);
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mine = [flag(vote.forced), flag(vote.any_far), d1, d2];
        let world = SimpleCommunicator::world();
        let mut all = vec![0.0 as Real; 4 * world.size() as usize];
        world.all_gather_into(&mine[..], &mut all[..]);
        let others = world.size() as u64 - 1;
        let bytes = std::mem::size_of_val(&mine) as u64 * others;
        self.bytes.fetch_add(bytes, Ordering::Relaxed);
        self.messages.fetch_add(others, Ordering::Relaxed);
        let forced = all.chunks(4).any(|v| v[0] != 0.0);
        let any_far = all.chunks(4).any(|v| v[1] != 0.0);
        let rebuild = forced
            || (any_far && {
                let mut moves: Vec<Real> = all.chunks(4).flat_map(|v| [v[2], v[3]]).collect();
                moves.sort_by(|a, b| b.total_cmp(a));
                vote.broad_phase
                    .moves_reach_skin(moves[0], moves[1], vote.walls)
            });
        self.last.store(rebuild, Ordering::Relaxed);
        rebuild
    }
}
