//! Deterministic data parallelism for the step: per-item work on rayon's current thread pool, results in
//! item order, whatever the number of threads.
//!
//! The step's parallel stages (narrow phase and laws, the per-body force sums, the integration with the
//! finiteness checks, the broad phase's pair search) compute one independent result per item (candidate
//! pair or body) and write it into that item's own slot; nothing is summed across items in parallel. The
//! force on a body is the sum over the body's own pairs, taken by that body's item in the fixed candidate
//! order (the rows of [`crate::world::contact_store::BodyAdjacency`]); the sums over all candidates (energy
//! terms, counters that feed physics) are taken serially in candidate order. A per-item result is a
//! function of the item's inputs only (the per-chunk scratch holds nothing that matters after a query), so
//! the state after a step is the same bit for bit for 1, 2 or N threads, and the same as the serial path's
//! — `tests/world_parallel.rs` proves it. Errors found per item (a failed query, a non-finite body) are
//! reported for the first failing item in item order.
//!
//! Per step there are three parallel regions when everything is above the thresholds: first half kick and
//! drift; narrow phase and laws (fused); force sums, second half kick and checks (fused per body when no
//! stage reads the loads in between: no sleeping, no prescribed body; else two regions). Each region
//! costs a fork/join and, on an idle machine, the wake-up of the pool's threads (see below). The broad phase's
//! search adds one on the steps that rebuild the grid.
//!
//! Work is split into contiguous chunks of items, a few per thread ([`CHUNKS_PER_THREAD`]), each with its
//! own [`Worker`] scratch (EPA buffers and narrow-phase counters) taken from a vector kept in the step's
//! scratch: no locks, no allocation once warm. Every chunk is a rayon job of its own (`with_max_len(1)`),
//! so a thread that runs dry steals single chunks and the threads of a region end within about one chunk
//! of each other (rayon's default split stops at runs of a quarter of the chunks on two threads unless
//! they are stolen, and a run one thread has started cannot be shared any more: the expensive candidates
//! around a projectile are contiguous in candidate order). The load balance per region is measured by
//! [`super::region_profile`] (`perf_threads --profile`): on the struck bed of 10⁴ polyhedra the costliest
//! chunk of the narrow phase holds ~6 % of a thread's share, so chunking alone leaves the
//! threads ≤ ~3 % apart. Errors are reported deterministically: each chunk stops at
//! its first failing item and the error of the lowest failing chunk wins, which is the first failing item
//! in item order.
//!
//! Small scenes run serially: below [`Parallelism::min_candidates`] candidates (narrow phase, laws, force
//! sums) or [`Parallelism::min_bodies`] units of integration work (`integration_work`: a body with
//! unequal principal moments counts [`ANISOTROPIC_WEIGHT`]) the fork/join overhead of rayon exceeds the
//! work.
//!
//! # Where the thresholds come from
//! A region of `n` items of cost `c` on two threads saves `n c / 2` and costs a fork/join overhead `o`, so
//! it pays from `n* = 2 o / c`. Waking threads that have fallen asleep costs far more than handing work
//! to spinning ones, and the thresholds take that case, so that a region never costs more than it saves
//! on an idle machine. The measured `o` and `c` and the resulting `n*` are in `docs/tuning.md`
//! (`cargo run --release --example perf_threads -- --overhead` measures them again).

use rayon::prelude::*;

use crate::contact::{EpaScratch, QueryCounters};

use super::region_profile;

/// Chunks per thread: more than one so that a thread finishing early takes work from a slow one (contact
/// queries differ in cost by 10× between a cached rejection and an EPA run), few enough that the per-chunk
/// overhead stays small. At the end of a region one thread waits on average for half a chunk of the
/// other's: with `k` chunks per thread on two threads that is `1 / (8 k)` of the serial work, 1.6 % of the
/// region at 8, 0.4 % at 32 (for chunks of equal cost; the costliest chunk of the struck bed costs about
/// twice the mean). A chunk costs a [`Worker`] (kept between steps), a result slot and a rayon job (a
/// push and pop of the thread's own deque, or a steal of ~1 µs where a thread runs dry), so 32 chunks of
/// the ~360 candidates of a 10⁴-polyhedra bed (~150 µs each) cost nothing measurable.
pub const CHUNKS_PER_THREAD: usize = 32;

/// Default [`Parallelism::min_candidates`]: 4096 candidate pairs, about three times the break-even count
/// of the cheapest candidates (those the cached axis or the bounding spheres reject), since a region
/// also holds the force sums (figures: `docs/tuning.md`).
pub const DEFAULT_MIN_CANDIDATES: usize = 4096;

/// Default [`Parallelism::min_bodies`]: 8192 units of integration work (`integration_work`), a small
/// margin above the break-even count of a sphere's kick and drift (figures: `docs/tuning.md`): 10⁴ spheres
/// integrate in parallel, a few thousand bodies at rest stay serial. Tumbling polyhedra cost several
/// times more ([`ANISOTROPIC_WEIGHT`]): 2048 of them are enough.
pub const DEFAULT_MIN_BODIES: usize = 8192;

/// Weight of a dynamic body with unequal principal moments in the integration's work
/// (`integration_work`): its rotation splitting (three sub-rotations per drift) costs about this many
/// sphere kicks and drifts (the ratio of the two measured with `examples/perf_threads.rs`: `docs/tuning.md`).
pub const ANISOTROPIC_WEIGHT: usize = 4;

/// When the step uses more than one thread. Threads come from rayon's current pool (the global pool, or
/// the one a caller `install`s); the results do not depend on the choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parallelism {
    /// Narrow phase and laws run in parallel from this many candidates on.
    pub min_candidates: usize,
    /// The integration runs in parallel from this much work on (`integration_work`: bodies, a body with
    /// unequal principal moments counting [`ANISOTROPIC_WEIGHT`]).
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

/// Per-chunk scratch of the narrow phase: nothing in it matters after the step's accumulation.
#[derive(Clone, Debug, Default)]
pub struct Worker {
    /// Scratch of EPA (polytope buffers), reused across queries.
    pub epa: EpaScratch,
    /// Counters of the queries of this chunk.
    pub query: QueryCounters,
    /// Items of this chunk that the caller marked for a serial pass after the region, in item order
    /// (cleared by `for_each_chunked`). Chunks are contiguous ranges of items in chunk order, so the
    /// lists of the workers taken in order are the marked items in item order, for any number of chunks:
    /// a serial pass over them sees the same items in the same order as one over all items that skips the
    /// unmarked ones.
    pub picked: Vec<u32>,
    /// Items of this chunk counted by the caller (cleared by `for_each_chunked`).
    pub tally: u64,
}

/// Items per chunk of a region of `n` items on the current pool: [`CHUNKS_PER_THREAD`] chunks per thread.
#[inline]
fn chunk_len(n: usize) -> usize {
    n.div_ceil(rayon::current_num_threads() * CHUNKS_PER_THREAD)
        .max(1)
}

/// Whether a region of `n` items runs on the pool.
#[inline]
fn on_pool(parallel: bool, n: usize) -> bool {
    parallel && n >= 2 && rayon::current_num_threads() > 1
}

/// Calls `f(i, &mut states[i], &mut out[i], worker)` for every item `i`, on the current rayon pool when
/// `parallel` (in chunks, one [`Worker`] per chunk), else serially with `workers[0]`. Returns the error of
/// the first failing item in item order. `workers` is resized to the number of chunks; its counters are
/// left for the caller to merge.
///
/// Every chunk is a job of its own (`with_max_len(1)`): a thread that runs dry steals single chunks, so
/// the threads end within about one chunk of each other however the cost is spread over the items (a
/// struck region's expensive pairs are contiguous in candidate order). Rayon's default adaptive split
/// stops at a few large runs of chunks unless they are stolen, and a run taken by one thread could not be
/// shared any more.
pub(crate) fn for_each_chunked<S, O, E, F>(
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
    for worker in workers.iter_mut() {
        worker.picked.clear();
        worker.tally = 0;
    }
    let n = states.len();
    if !on_pool(parallel, n) {
        if workers.is_empty() {
            workers.push(Worker::default());
        }
        let worker = &mut workers[0];
        for (i, (s, o)) in states.iter_mut().zip(out.iter_mut()).enumerate() {
            f(i, s, o, worker)?;
        }
        return Ok(());
    }
    let size = chunk_len(n);
    let chunks = n.div_ceil(size);
    if workers.len() < chunks {
        workers.resize_with(chunks, Worker::default);
    }
    let results: Vec<Result<(), E>> = states
        .par_chunks_mut(size)
        .zip(out.par_chunks_mut(size))
        .zip(workers[..chunks].par_iter_mut())
        .with_max_len(1)
        .enumerate()
        .map(|(k, ((s, o), worker))| {
            let _timer = region_profile::chunk();
            for (j, (s, o)) in s.iter_mut().zip(o.iter_mut()).enumerate() {
                f(k * size + j, s, o, worker)?;
            }
            Ok(())
        })
        .collect();
    results.into_iter().collect()
}

/// Calls `f(i, &mut items[i])` for every item, in parallel when `parallel` (chunks of items, each a job:
/// see `for_each_chunked`; `f` must not depend on the order).
pub fn for_each_item<T, F>(parallel: bool, items: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize, &mut T) + Sync + Send,
{
    if on_pool(parallel, items.len()) {
        let size = chunk_len(items.len());
        items
            .par_chunks_mut(size)
            .with_max_len(1)
            .enumerate()
            .for_each(|(k, chunk)| {
                let _timer = region_profile::chunk();
                for (j, t) in chunk.iter_mut().enumerate() {
                    f(k * size + j, t);
                }
            });
    } else {
        for (i, t) in items.iter_mut().enumerate() {
            f(i, t);
        }
    }
}

/// Calls `f(i, &mut items[i])` for every item, in parallel when `parallel`, and returns the first item (in
/// item order) for which `f` returned an error, with that error. Every item is visited whatever fails, so
/// the items end in the same state for any number of threads.
pub(crate) fn for_each_item_checked<T, E, F>(
    parallel: bool,
    items: &mut [T],
    f: F,
) -> Option<(usize, E)>
where
    T: Send,
    E: Send,
    F: Fn(usize, &mut T) -> Option<E> + Sync + Send,
{
    if on_pool(parallel, items.len()) {
        let size = chunk_len(items.len());
        items
            .par_chunks_mut(size)
            .with_max_len(1)
            .enumerate()
            .filter_map(|(k, chunk)| {
                let _timer = region_profile::chunk();
                let mut first = None;
                for (j, t) in chunk.iter_mut().enumerate() {
                    let i = k * size + j;
                    if let Some(e) = f(i, t) {
                        first.get_or_insert((i, e));
                    }
                }
                first
            })
            .min_by_key(|(i, _)| *i)
    } else {
        let mut first = None;
        for (i, t) in items.iter_mut().enumerate() {
            if let Some(e) = f(i, t) {
                first.get_or_insert((i, e));
            }
        }
        first
    }
}

/// Calls `f(i, &mut a[i], &mut b[i], &mut c[i])` for every item, in parallel when `parallel`, and returns
/// the first item (in item order) for which `f` returned an error, with that error. Every item is visited
/// whatever fails, so the items end in the same state for any number of threads.
pub(crate) fn for_each_item3_checked<A, B, C, E, F>(
    parallel: bool,
    a: &mut [A],
    b: &mut [B],
    c: &mut [C],
    f: F,
) -> Option<(usize, E)>
where
    A: Send,
    B: Send,
    C: Send,
    E: Send,
    F: Fn(usize, &mut A, &mut B, &mut C) -> Option<E> + Sync + Send,
{
    debug_assert!(a.len() == b.len() && a.len() == c.len());
    if on_pool(parallel, a.len()) {
        let size = chunk_len(a.len());
        a.par_chunks_mut(size)
            .zip(b.par_chunks_mut(size))
            .zip(c.par_chunks_mut(size))
            .with_max_len(1)
            .enumerate()
            .filter_map(|(k, ((xs, ys), zs))| {
                let _timer = region_profile::chunk();
                let mut first = None;
                for (j, ((x, y), z)) in xs
                    .iter_mut()
                    .zip(ys.iter_mut())
                    .zip(zs.iter_mut())
                    .enumerate()
                {
                    let i = k * size + j;
                    if let Some(e) = f(i, x, y, z) {
                        first.get_or_insert((i, e));
                    }
                }
                first
            })
            .min_by_key(|(i, _)| *i)
    } else {
        let mut first = None;
        for (i, ((x, y), z)) in a.iter_mut().zip(b.iter_mut()).zip(c.iter_mut()).enumerate() {
            if let Some(e) = f(i, x, y, z) {
                first.get_or_insert((i, e));
            }
        }
        first
    }
}

/// Calls `f(i, &mut a[i], &mut b[i], &mut c[i], &mut d[i])` for every item, in parallel when `parallel`
/// (the chunks and jobs of [`for_each_item3`]; `f` must not depend on the order).
pub(crate) fn for_each_item4<A, B, C, D, F>(
    parallel: bool,
    a: &mut [A],
    b: &mut [B],
    c: &mut [C],
    d: &mut [D],
    f: F,
) where
    A: Send,
    B: Send,
    C: Send,
    D: Send,
    F: Fn(usize, &mut A, &mut B, &mut C, &mut D) + Sync + Send,
{
    debug_assert!(a.len() == b.len() && a.len() == c.len() && a.len() == d.len());
    if on_pool(parallel, a.len()) {
        let size = chunk_len(a.len());
        a.par_chunks_mut(size)
            .zip(b.par_chunks_mut(size))
            .zip(c.par_chunks_mut(size))
            .zip(d.par_chunks_mut(size))
            .with_max_len(1)
            .enumerate()
            .for_each(|(k, (((xs, ys), zs), ws))| {
                let _timer = region_profile::chunk();
                for (j, (((x, y), z), w)) in xs
                    .iter_mut()
                    .zip(ys.iter_mut())
                    .zip(zs.iter_mut())
                    .zip(ws.iter_mut())
                    .enumerate()
                {
                    f(k * size + j, x, y, z, w);
                }
            });
    } else {
        for (i, (((x, y), z), w)) in a
            .iter_mut()
            .zip(b.iter_mut())
            .zip(c.iter_mut())
            .zip(d.iter_mut())
            .enumerate()
        {
            f(i, x, y, z, w);
        }
    }
}

/// Calls `f(i, &mut a[i], &mut b[i], &mut c[i])` for every item, in parallel when `parallel` (chunks of
/// items, each a job; `f` must not depend on the order).
pub(crate) fn for_each_item3<A, B, C, F>(
    parallel: bool,
    a: &mut [A],
    b: &mut [B],
    c: &mut [C],
    f: F,
) where
    A: Send,
    B: Send,
    C: Send,
    F: Fn(usize, &mut A, &mut B, &mut C) + Sync + Send,
{
    // The checked form with nothing to report: the same chunks, jobs and order.
    for_each_item3_checked(parallel, a, b, c, |i, x, y, z| {
        f(i, x, y, z);
        None::<()>
    });
}

/// Fills `out[i] = f(i)` for every `i` in `0..out.len()`, in parallel when `parallel` (each slot written
/// once, by its own item: the same values for any number of threads).
pub fn fill_items<T, F>(parallel: bool, out: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize) -> T + Sync + Send,
{
    for_each_item(parallel, out, |i, slot| *slot = f(i));
}

/// Calls `f(i, &mut a[i], &mut b[i])` for every item, in parallel when `parallel` (chunks of items, each a
/// job; `f` must not depend on the order).
pub(crate) fn for_each_item_pair<A, B, F>(parallel: bool, a: &mut [A], b: &mut [B], f: F)
where
    A: Send,
    B: Send,
    F: Fn(usize, &mut A, &mut B) + Sync + Send,
{
    debug_assert_eq!(a.len(), b.len());
    if on_pool(parallel, a.len()) {
        let size = chunk_len(a.len());
        a.par_chunks_mut(size)
            .zip(b.par_chunks_mut(size))
            .with_max_len(1)
            .enumerate()
            .for_each(|(k, (xs, ys))| {
                let _timer = region_profile::chunk();
                for (j, (x, y)) in xs.iter_mut().zip(ys.iter_mut()).enumerate() {
                    f(k * size + j, x, y);
                }
            });
    } else {
        for (i, (x, y)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
            f(i, x, y);
        }
    }
}

/// The integration's work in units of a sphere's kick and drift, compared with
/// [`Parallelism::min_bodies`]: `bodies` plus [`ANISOTROPIC_WEIGHT`] − 1 more per dynamic body with unequal
/// principal moments.
pub(crate) fn integration_work(bodies: usize, anisotropic: usize) -> usize {
    bodies + (ANISOTROPIC_WEIGHT - 1) * anisotropic
}
