//! Deterministic data parallelism for the step: per-item work on rayon's current thread pool, results in
//! item order, whatever the number of threads.
//!
//! The step's parallel stages (narrow phase, laws, integration) compute one independent result per item
//! (candidate pair or body) and write it into that item's own slot; nothing is summed across items in
//! parallel. Every sum over items (forces on a body, energy terms, counters that feed physics) is taken
//! afterwards, serially, in the fixed item order. A per-item result is a function of the item's inputs only
//! (the per-chunk scratch holds nothing that matters after a query), so the state after a step is the same
//! bit for bit for 1, 2 or N threads — `tests/world_parallel.rs` proves it.
//!
//! Work is split into contiguous chunks of items, a few per thread ([`CHUNKS_PER_THREAD`]), each with its
//! own [`Worker`] scratch (EPA buffers and narrow-phase counters) taken from a vector kept in the step's
//! scratch: no locks, no allocation once warm. Errors are reported deterministically: each chunk stops at
//! its first failing item and the error of the lowest failing chunk wins, which is the first failing item
//! in item order.
//!
//! Small scenes run serially: below [`Parallelism::min_candidates`] candidates (or
//! [`Parallelism::min_bodies`] bodies for the integration) the fork/join overhead of rayon (a few µs per
//! stage) exceeds the work; see [`DEFAULT_MIN_CANDIDATES`] for the measurement behind the defaults.

use rayon::prelude::*;

use crate::contact::{EpaScratch, QueryCounters};

/// Chunks per thread: more than one so that a thread finishing early takes work from a slow one (contact
/// queries differ in cost by 10× between a cached rejection and an EPA run), few enough that the per-chunk
/// overhead stays small.
pub const CHUNKS_PER_THREAD: usize = 8;

/// Default [`Parallelism::min_candidates`]: 128 candidate pairs. Measured with `benches/step.rs` (group
/// `threshold`, stages forced serial or parallel, 2 threads, 2026-11-21 on the shared 2-core machine at a
/// load average of ~10, so only the small scenes are conclusive): 22 candidates 18 µs serial vs 22 µs
/// parallel per step, 75 candidates 37 vs 58 µs, 241 candidates 224 vs 141 µs. The threshold lies between
/// the last two.
pub const DEFAULT_MIN_CANDIDATES: usize = 128;

/// Default [`Parallelism::min_bodies`]: 512 bodies. The fork/joins of the 64-body scene above cost ~5 µs
/// each (21 µs for four parallel regions); a half kick and drift cost ~250 ns per body (integrate stage of
/// the 10^4-polyhedra bench), so from ~500 bodies on the integration is worth ≥ 25 fork/joins.
pub const DEFAULT_MIN_BODIES: usize = 512;

/// When the step uses more than one thread. Threads come from rayon's current pool (the global pool, or
/// the one a caller `install`s); the results do not depend on the choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parallelism {
    /// Narrow phase and laws run in parallel from this many candidates on.
    pub min_candidates: usize,
    /// The integration runs in parallel from this many bodies on.
    pub min_bodies: usize,
}

impl Default for Parallelism {
    fn default() -> Self {
        Self {
            min_candidates: DEFAULT_MIN_CANDIDATES,
            min_bodies: DEFAULT_MIN_BODIES,
        }
    }
}

/// Per-chunk scratch of the narrow phase: nothing in it matters after a query.
#[derive(Clone, Debug, Default)]
pub struct Worker {
    pub epa: EpaScratch,
    pub query: QueryCounters,
}

/// Calls `f(i, &mut states[i], &mut out[i], worker)` for every item `i`, on the current rayon pool when
/// `parallel` (in chunks, one [`Worker`] per chunk), else serially with `workers[0]`. Returns the error of
/// the first failing item in item order. `workers` is resized to the number of chunks; its counters are
/// left for the caller to merge.
pub fn for_each_chunked<S, O, E, F>(
    parallel: bool,
    states: &mut [S],
    out: &mut [O],
    workers: &mut Vec<Worker>,
    f: F,
) -> Result<(), E>
where
    S: Send,
    O: Send,
    E: Send,
    F: Fn(usize, &mut S, &mut O, &mut Worker) -> Result<(), E> + Sync,
{
    debug_assert_eq!(states.len(), out.len());
    let n = states.len();
    let threads = rayon::current_num_threads();
    if !parallel || threads < 2 || n < 2 {
        if workers.is_empty() {
            workers.push(Worker::default());
        }
        let worker = &mut workers[0];
        for (i, (s, o)) in states.iter_mut().zip(out.iter_mut()).enumerate() {
            f(i, s, o, worker)?;
        }
        return Ok(());
    }
    let chunks = (threads * CHUNKS_PER_THREAD).min(n);
    let size = n.div_ceil(chunks);
    let chunks = n.div_ceil(size);
    if workers.len() < chunks {
        workers.resize_with(chunks, Worker::default);
    }
    let results: Vec<Result<(), E>> = states
        .par_chunks_mut(size)
        .zip(out.par_chunks_mut(size))
        .zip(workers[..chunks].par_iter_mut())
        .enumerate()
        .map(|(k, ((s, o), worker))| {
            for (j, (s, o)) in s.iter_mut().zip(o.iter_mut()).enumerate() {
                f(k * size + j, s, o, worker)?;
            }
            Ok(())
        })
        .collect();
    results.into_iter().collect()
}

/// Calls `f(i, &mut items[i])` for every item, in parallel when `parallel` (work split by rayon; `f` must
/// not depend on the order).
pub fn for_each_item<T, F>(parallel: bool, items: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize, &mut T) + Sync + Send,
{
    if parallel && rayon::current_num_threads() > 1 {
        let min_len = items
            .len()
            .div_ceil(rayon::current_num_threads() * CHUNKS_PER_THREAD);
        items
            .par_iter_mut()
            .with_min_len(min_len.max(1))
            .enumerate()
            .for_each(|(i, t)| f(i, t));
    } else {
        for (i, t) in items.iter_mut().enumerate() {
            f(i, t);
        }
    }
}
