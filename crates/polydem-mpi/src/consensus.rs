//! The broad-phase rebuild decision of the whole world, taken by every part.
//!
//! One process rebuilds when a wall or the body count forces it, or when some body moved half the skin and
//! the two largest body moves (with the walls') may have brought a pair within reach. The two largest moves
//! of the whole world are the two largest of the ranks' owned pairs (each body counted once, where it is
//! owned), so one all-reduce of four numbers gives every part the same decision as one process: its
//! combination keeps either flag and the two largest moves of both sides, a choice among values, never a
//! sum, so the result does not depend on the order in which MPI combines the ranks (O(log P) per step).

use std::ffi::{c_int, c_void};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use mpi::collective::UnsafeUserOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use polydem::math::Real;
use polydem::world::{RebuildConsensus, RebuildVote};

use crate::exchange::Traffic;

/// The decision of one part, agreed with the other ranks at every stage 3 (the part's world counts the
/// bodies it owns: `World::count_only`).
#[derive(Debug, Default)]
pub struct Consensus {
    /// The decision of the last call (whether the last stage 3 rebuilt).
    last: AtomicBool,
    /// Bytes this rank handed to the agreements' all-reduces.
    bytes: AtomicU64,
    /// The agreements' all-reduces (one per agreement on more than one rank).
    messages: AtomicU64,
}

impl Consensus {
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
        let (d1, d2) = vote.largest_moves_sq;
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mine: Vote = [flag(vote.forced), flag(vote.any_far), d1, d2];
        let world = SimpleCommunicator::world();
        let mut all: Vote = [0.0; VOTE_WORDS];
        if world.size() > 1 {
            // SAFETY: `merge_votes` reads and writes the buffers MPI hands it as the f64 arrays of this
            // call, whose datatype is f64.
            let merge = unsafe { UnsafeUserOperation::commutative(merge_votes) };
            world.all_reduce_into(&mine[..], &mut all[..], &merge);
            self.bytes
                .fetch_add(std::mem::size_of_val(&mine) as u64, Ordering::Relaxed);
            self.messages.fetch_add(1, Ordering::Relaxed);
        } else {
            all = mine;
        }
        let [forced, any_far, d1, d2] = all;
        let rebuild = forced != 0.0
            || (any_far != 0.0 && vote.broad_phase.moves_reach_skin(d1, d2, vote.walls));
        self.last.store(rebuild, Ordering::Relaxed);
        rebuild
    }
}

/// One rank's vote: whether a rebuild is forced, whether a body moved half the skin, and the two largest
/// squared moves of its owned bodies (the largest first).
type Vote = [Real; VOTE_WORDS];
const VOTE_WORDS: usize = 4;

/// Two votes combined into `into`: either flag, the two largest moves of the four (a multiset, by
/// `total_cmp` as a sort of all the ranks' moves would take them).
fn merge(from: &[Real], into: &mut [Real]) {
    into[0] = if from[0] != 0.0 { from[0] } else { into[0] };
    into[1] = if from[1] != 0.0 { from[1] } else { into[1] };
    let mut moves = [from[2], from[3], into[2], into[3]];
    moves.sort_by(|a, b| b.total_cmp(a));
    into[2] = moves[0];
    into[3] = moves[1];
}

/// [`merge`] over `len` votes, as MPI calls a user operation.
///
/// # Safety
/// `invec` and `inoutvec` point to `*len` f64 each (the datatype of the all-reduce in
/// [`Consensus::decide`]), not overlapping.
unsafe extern "C" fn merge_votes(
    invec: *mut c_void,
    inoutvec: *mut c_void,
    len: *mut c_int,
    _datatype: *mut mpi::ffi::MPI_Datatype,
) {
    // SAFETY: the caller's contract above.
    let (from, into) = unsafe {
        let n = *len as usize;
        (
            std::slice::from_raw_parts(invec as *const Real, n),
            std::slice::from_raw_parts_mut(inoutvec as *mut Real, n),
        )
    };
    for (f, i) in from
        .chunks_exact(VOTE_WORDS)
        .zip(into.chunks_exact_mut(VOTE_WORDS))
    {
        merge(f, i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Merging the ranks' votes in any order gives the flags of any rank and the two largest moves of all,
    /// ties counted twice, as the all-gather and sort it replaces.
    #[test]
    fn merged_votes_are_the_sorted_moves_whatever_the_order() {
        let votes: [Vote; 4] = [
            [0.0, 0.0, 3.0, 1.0],
            [0.0, 1.0, 2.0, 2.0],
            [0.0, 0.0, 3.0, 0.5],
            [1.0, 0.0, 0.0, 0.0],
        ];
        for order in [[0, 1, 2, 3], [3, 2, 1, 0], [2, 0, 3, 1], [1, 3, 0, 2]] {
            let mut acc = votes[order[0]];
            for &k in &order[1..] {
                merge(&votes[k], &mut acc);
            }
            assert_eq!(acc, [1.0, 1.0, 3.0, 3.0], "order {order:?}");
        }
        let mut acc = votes[1];
        merge(&votes[3], &mut acc);
        assert_eq!(acc, [1.0, 1.0, 2.0, 2.0], "ties within one vote");
    }
}
