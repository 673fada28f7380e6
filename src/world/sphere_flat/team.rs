//! Static work sharing for the flat path's parallel passes: part k of a pass always runs on thread k of
//! rayon's pool, and the threads leave a pass together.
//!
//! The flat step has three per-sphere or per-pair passes (drift, pair loop, kick). With rayon's work
//! stealing, whichever thread is free takes a chunk, so the spheres one thread drifted are often paired
//! or kicked by the other, and their records (positions, velocities, springs, pair outputs: ~3 MB for the
//! 3000-sphere beds) move between the cores' caches from pass to pass. A broadcast job is never stolen:
//! giving part k to the thread of index k keeps each block's spheres and pairs on one core (the blocks
//! are made for the pool, one per thread: [`super::step::Blocks`]). The results do not depend on which
//! thread computes a part, so the bits are the same as serial.
//!
//! A thread that ends its part first spins until the others end theirs ([`spin_until_all`]) instead of
//! returning to rayon, whose idle loop soon puts it to sleep: starting and joining the other thread cost
//! ~3–8 µs per pass on the 2-core VM (per-thread timestamps, 2026-11-22 (late)).
//!
//! The spin holds a thread until every thread of the pool has run its part, so a pass needs all of the
//! pool's threads: a caller that steps several flat simulations at once from jobs of one pool makes each
//! wait until the others' threads come back to rayon (their next pass or join); nothing in polydem does
//! (the suite steps one simulation at a time, on its own pool).

use std::sync::atomic::{AtomicUsize, Ordering};
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
    fn split_follows_the_ranges() {
        let mut v: Vec<u32> = (0..7).collect();
        let pieces = split_at_ranges(&mut v, &[0..3, 3..3, 3..7]);
        let lens: Vec<usize> = pieces.iter().map(|p| p.len()).collect();
        assert_eq!(lens, vec![3, 0, 4]);
        assert_eq!(pieces[2][0], 3);
    }
}
