//! Static work sharing for the flat path's parallel passes: part k of a pass always runs on thread k of
//! rayon's pool, and the threads leave a pass together.
//!
//! The flat step has three per-sphere or per-pair passes (drift, pair loop, kick). With rayon's work
//! stealing, whichever thread is free takes a chunk, so the spheres one thread drifted are often paired
//! or kicked by the other, and their records (positions, velocities, springs, pair outputs: ~3 MB for the
//! 3000-sphere beds) move between the cores' caches from pass to pass. A broadcast job is never stolen:
//! giving part k to the thread of index k keeps each block's spheres and pairs on one core (the blocks
//! are made for the pool, one per thread: [`super::blocks::Blocks`]). The results do not depend on which
//! thread computes a part, so the bits are the same as serial. Only the middles between neighbouring
//! parts are shared out while the pass runs ([`TwoEnded`]): the faster of two neighbours takes more of
//! them, and most records still stay on one core.
//!
//! A thread that ends its part first spins until the others end theirs ([`spin_until_all`]) instead of
//! returning to rayon, whose idle loop soon puts it to sleep and makes waking it cost more than the
//! spin (`docs/tuning.md`). A step
//! whose lists hold runs its three passes as one job, with a [`Barrier`] between them and the arrays
//! shared as [`PhaseSlice`]s (`super::fused`); [`for_each_part`] runs the passes of the other steps.
//!
//! The spin holds a thread until every thread of the pool has run its part, so a pass needs all of the
//! pool's threads: a caller that steps several flat simulations at once from jobs of one pool makes each
//! wait until the others' threads come back to rayon (their next pass or join); nothing in polydem does
//! (the suite steps one simulation at a time, on its own pool).

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How long a thread that ended its part spins before it also yields its core at each check: on a
/// shared host the thread it waits for may have been descheduled.
const SPIN_LIMIT: Duration = Duration::from_micros(100);

/// Runs `work(k, part)` on each of `parts`, part k on thread k mod T of rayon's current pool of T threads
/// (`rayon::broadcast`), and returns the results in part order.
pub(super) fn for_each_part<P: Send, R: Send>(
    parts: Vec<P>,
    work: impl Fn(usize, P) -> R + Sync,
) -> Vec<R> {
    let n = parts.len();
    let slots: Vec<Mutex<Option<P>>> = parts.into_iter().map(|p| Mutex::new(Some(p))).collect();
    let arrived = AtomicUsize::new(0);
    let per_thread: Vec<Vec<(usize, R)>> = rayon::broadcast(|ctx| {
        let threads = ctx.num_threads().max(1);
        let done: Vec<(usize, R)> = (ctx.index()..n)
            .step_by(threads)
            .filter_map(|k| {
                // Each slot is taken by exactly one thread (k mod T), so the lock is never contended.
                let part = slots[k]
                    .lock()
                    .unwrap_or_else(|poisoned| poisoned.into_inner())
                    .take();
                part.map(|p| (k, work(k, p)))
            })
            .collect();
        let busy = n.min(threads);
        if ctx.index() < busy {
            spin_until_all(&arrived, busy);
        }
        done
    });
    let mut results: Vec<Option<R>> = (0..n).map(|_| None).collect();
    for (k, r) in per_thread.into_iter().flatten() {
        results[k] = Some(r);
    }
    results
        .into_iter()
        .map(|r| r.expect("every part runs on the thread of its index"))
        .collect()
}

/// Counts this thread in at `arrived` and waits until `all` threads have arrived.
fn spin_until_all(arrived: &AtomicUsize, all: usize) {
    arrived.fetch_add(1, Ordering::AcqRel);
    let start = Instant::now();
    let mut spins = 0u32;
    while arrived.load(Ordering::Acquire) < all {
        std::hint::spin_loop();
        spins = spins.wrapping_add(1);
        if spins.is_multiple_of(64) && start.elapsed() > SPIN_LIMIT {
            std::thread::yield_now();
        }
    }
}

/// The barriers between the phases of one job that every thread of the team runs (`super::fused`):
/// the k-th [`Barrier::wait`] of each thread returns once all `threads` have made their k-th call.
/// What a thread wrote before a wait is visible to every thread after it (the count is released and
/// acquired).
pub(super) struct Barrier {
    arrived: AtomicUsize,
    threads: usize,
}

impl Barrier {
    pub(super) fn new(threads: usize) -> Self {
        Self {
            arrived: AtomicUsize::new(0),
            threads,
        }
    }

    /// Waits for the `round`-th time (1, 2, …: each thread counts its own calls).
    pub(super) fn wait(&self, round: usize) {
        spin_until_all(&self.arrived, round * self.threads);
    }
}

/// A slice that the threads of one team job write in disjoint parts in one phase and read whole in
/// another, the phases separated by a [`Barrier`]: what the borrow checker cannot see across the
/// phases of one job, the caller promises (see [`PhaseSlice::part`], [`PhaseSlice::whole`]).
pub(super) struct PhaseSlice<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: a PhaseSlice is a `&mut [T]` handed to several threads; the callers of `part` and `whole`
// keep the accesses of different threads disjoint or read-only within each phase.
unsafe impl<T: Send> Send for PhaseSlice<'_, T> {}
unsafe impl<T: Send + Sync> Sync for PhaseSlice<'_, T> {}

impl<'a, T> PhaseSlice<'a, T> {
    pub(super) fn new(slice: &'a mut [T]) -> Self {
        Self {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _borrow: std::marker::PhantomData,
        }
    }

    /// The items of `range`, to write.
    ///
    /// # Safety
    /// Until the reference is dropped, which must happen before the phase ends, no other reference to
    /// an item of `range` exists: no other thread's part overlaps it and no thread holds the slice
    /// [`whole`](Self::whole) in this phase.
    #[allow(clippy::mut_from_ref)]
    pub(super) unsafe fn part(&self, range: std::ops::Range<usize>) -> &mut [T] {
        assert!(
            range.start <= range.end && range.end <= self.len,
            "part {range:?} of a slice of {}",
            self.len
        );
        // SAFETY: in bounds (asserted); exclusive by the caller's promise.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(range.start), range.len()) }
    }

    /// The whole slice, to read.
    ///
    /// # Safety
    /// Until the reference is dropped, which must happen before the phase ends, no thread holds a
    /// [`part`](Self::part) of the slice.
    pub(super) unsafe fn whole(&self) -> &[T] {
        // SAFETY: the slice this was made from, read-only by the caller's promise.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

/// A range of items that two threads share out while they run: one takes pieces from its front, the
/// other from its back, until they meet; every item is taken once (the middles of the pair loop,
/// [`super::blocks::Blocks`]). The pieces shrink as the range does (a quarter of what is left, at
/// least [`MIN_PIECE`]), so the threads take few pieces while far apart and end within a small piece of
/// each other.
pub(super) struct TwoEnded {
    /// The front (high 32 bits) and the back (low 32 bits) of what is left.
    ends: AtomicU64,
}

/// The smallest piece of a [`TwoEnded`]: 16 spheres' rows of the pair loop cost several times a
/// compare-and-swap whose cache line the other core holds (`docs/tuning.md`).
const MIN_PIECE: usize = 16;

impl TwoEnded {
    pub(super) fn new(range: std::ops::Range<usize>) -> Self {
        let (front, back) = (
            u32::try_from(range.start).expect("a middle's start fits in 32 bits"),
            u32::try_from(range.end.max(range.start)).expect("a middle's end fits in 32 bits"),
        );
        Self {
            ends: AtomicU64::new((u64::from(front) << 32) | u64::from(back)),
        }
    }

    /// The next piece from the front, if any is left.
    pub(super) fn take_front(&self) -> Option<std::ops::Range<usize>> {
        self.take(|front, back| {
            let end = front + piece(back - front);
            (front..end, (end, back))
        })
    }

    /// The next piece from the back, if any is left.
    pub(super) fn take_back(&self) -> Option<std::ops::Range<usize>> {
        self.take(|front, back| {
            let start = back - piece(back - front);
            (start..back, (front, start))
        })
    }

    /// Takes the piece that `cut(front, back)` names (with the ends left after it), atomically.
    fn take(
        &self,
        cut: impl Fn(usize, usize) -> (std::ops::Range<usize>, (usize, usize)),
    ) -> Option<std::ops::Range<usize>> {
        let mut ends = self.ends.load(Ordering::Acquire);
        loop {
            let (front, back) = ((ends >> 32) as usize, (ends & 0xffff_ffff) as usize);
            if front >= back {
                return None;
            }
            let (piece, (front, back)) = cut(front, back);
            let left = ((front as u64) << 32) | back as u64;
            match self
                .ends
                .compare_exchange_weak(ends, left, Ordering::AcqRel, Ordering::Acquire)
            {
                Ok(_) => return Some(piece),
                Err(now) => ends = now,
            }
        }
    }
}

/// Thread `k`'s pieces of the middles beside its part, taken one at a time as the caller asks: the
/// middle after its part from the front, then the middle before it from the back (each piece with
/// whether it came from the back, i.e. lies before the thread's part), until the neighbours meet.
pub(super) fn pieces_of(
    middles: &[TwoEnded],
    k: usize,
) -> impl Iterator<Item = (std::ops::Range<usize>, bool)> + '_ {
    let front = middles
        .get(k)
        .into_iter()
        .flat_map(|m| std::iter::from_fn(|| m.take_front()));
    let back = k.checked_sub(1).and_then(|m| middles.get(m));
    let back = back
        .into_iter()
        .flat_map(|m| std::iter::from_fn(|| m.take_back()));
    front.map(|r| (r, false)).chain(back.map(|r| (r, true)))
}

/// The size of the next piece of a [`TwoEnded`] with `left` items left (at least one).
fn piece(left: usize) -> usize {
    (left / 4).max(MIN_PIECE).min(left)
}

/// `slice` cut into the consecutive pieces of `ranges` (which must tile `0..slice.len()` in order).
pub(super) fn split_at_ranges<'a, T>(
    mut slice: &'a mut [T],
    ranges: &[std::ops::Range<usize>],
) -> Vec<&'a mut [T]> {
    let mut pieces = Vec::with_capacity(ranges.len());
    for range in ranges {
        let (piece, rest) = std::mem::take(&mut slice).split_at_mut(range.len());
        pieces.push(piece);
        slice = rest;
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_come_back_in_order_on_any_pool() {
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for n in [0, 1, 2, 5] {
                let parts: Vec<usize> = (0..n).map(|k| 10 * k).collect();
                let got = pool.install(|| for_each_part(parts.clone(), |k, p| (k, p + 1)));
                let want: Vec<(usize, usize)> = (0..n).map(|k| (k, 10 * k + 1)).collect();
                assert_eq!(got, want, "{threads} threads, {n} parts");
            }
        }
    }

    #[test]
    fn each_part_runs_on_the_thread_of_its_index() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let got =
            pool.install(|| for_each_part(vec![(); 4], |_, ()| rayon::current_thread_index()));
        assert_eq!(got, vec![Some(0), Some(1), Some(0), Some(1)]);
    }

    #[test]
    fn barrier_orders_the_phases_of_a_job() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let mut v = vec![0u64; 8];
        let shared = PhaseSlice::new(&mut v);
        let barrier = Barrier::new(2);
        let sums = pool.install(|| {
            rayon::broadcast(|ctx| {
                let k = ctx.index();
                for round in 1..=3u64 {
                    // SAFETY: thread k writes items 4k..4k+4 only, then both read after the barrier.
                    let part = unsafe { shared.part(4 * k..4 * k + 4) };
                    part.iter_mut().for_each(|x| *x += round);
                    barrier.wait(2 * round as usize - 1);
                    // SAFETY: nobody writes between the two barriers of the round.
                    let sum: u64 = unsafe { shared.whole() }.iter().sum();
                    barrier.wait(2 * round as usize);
                    assert_eq!(
                        sum,
                        8 * round * (round + 1) / 2,
                        "thread {k}, round {round}"
                    );
                }
                k
            })
        });
        assert_eq!(sums, vec![0, 1]);
        assert_eq!(v, vec![6; 8]);
    }

    #[test]
    fn split_follows_the_ranges() {
        let mut v: Vec<u32> = (0..7).collect();
        let pieces = split_at_ranges(&mut v, &[0..3, 3..3, 3..7]);
        let lens: Vec<usize> = pieces.iter().map(|p| p.len()).collect();
        assert_eq!(lens, vec![3, 0, 4]);
        assert_eq!(pieces[2][0], 3);
    }

    #[test]
    fn two_ended_range_gives_every_item_once() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for range in [0..0, 5..6, 10..27, 100..1100] {
            for _ in 0..20 {
                let shared = TwoEnded::new(range.clone());
                let pieces = pool.install(|| {
                    rayon::broadcast(|ctx| {
                        let mut mine = Vec::new();
                        let take = || match ctx.index() {
                            0 => shared.take_front(),
                            _ => shared.take_back(),
                        };
                        while let Some(piece) = take() {
                            assert!(!piece.is_empty(), "empty piece {piece:?} of {range:?}");
                            mine.push(piece);
                        }
                        mine
                    })
                });
                let mut items: Vec<usize> = pieces.into_iter().flatten().flatten().collect();
                items.sort_unstable();
                let want: Vec<usize> = range.clone().collect();
                assert_eq!(items, want, "the pieces of {range:?}");
            }
        }
    }

    #[test]
    fn pieces_shrink_to_the_smallest() {
        let shared = TwoEnded::new(0..1000);
        assert_eq!(shared.take_front(), Some(0..250));
        assert_eq!(shared.take_back(), Some(813..1000));
        let mut last = 0..0;
        while let Some(p) = shared.take_front() {
            last = p;
        }
        assert!(last.len() <= MIN_PIECE, "last piece {last:?}");
    }
}
