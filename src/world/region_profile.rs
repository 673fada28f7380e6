//! Opt-in profile of the step's parallel regions and serial sections: per region, the CPU time each pool
//! thread spent in it (its load balance) and its wall time; per serial section, its CPU time.
//!
//! The step reaches it through its stage clocks ([`super::timing::StageClock`]), which time every stage
//! for the step's counters whether the profile is on or not, and through the chunk timers of
//! [`super::parallel`].
//!
//! Off by default (one relaxed atomic load per region, section and chunk). [`enable`] turns it on for the
//! whole process (`examples/perf_threads.rs --profile`); [`take`] returns and clears the figures. The
//! figures are CPU times of the threads (`CLOCK_THREAD_CPUTIME_ID`), not wall times, so that they stay
//! meaningful on a loaded machine, where a thread may wait for a core in the middle of a chunk:
//! - a region's **imbalance** is Σ over its runs of the busiest thread's CPU time, divided by Σ of the mean
//!   over the pool's threads (1.0: every thread did the same work; 2.0 on two threads: one did all);
//! - a section's CPU time on one thread, against the step's, is its share of the serial fraction.
//!
//! The profile observes only: nothing in the step reads it, so the results are the same bits with it on
//! or off. It is process-global (the regions of concurrent steps, e.g. parallel tests, would mix), which
//! is why it stays a diagnostic of the perf example.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The parallel regions and serial sections of the step that the profile tells apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    /// Stages 1–2 on the pool (first half kick, drift).
    KickDrift,
    /// Stage 3's pair search of a grid rebuild on the pool.
    BroadSearch,
    /// Stages 4–5 on the pool (narrow phase and laws).
    Narrow,
    /// Stage 6's per-body sums on the pool (alone, or fused with stages 7–8).
    Gather,
    /// Stages 7–8 on the pool (second half kick and checks, with the sums when fused).
    KickChecks,
    /// Serial: stage 3's per-body inputs, rebuild test and candidate list.
    SerialInputs,
    /// Serial: the grid build of a rebuild (everything but the parallel pair search) and the wall pairs.
    SerialGrid,
    /// Serial: the contact store's sync and the per-body adjacency rows.
    SerialStore,
    /// Serial: stage 6's sums in candidate order (report, ledger terms, scatter on one thread).
    SerialSums,
}

/// Number of [`Section`]s.
const SECTIONS: usize = 9;
/// The largest pool the profile follows (threads beyond it are counted as the last one).
const MAX_THREADS: usize = 64;

impl Section {
    /// Every section, in report order.
    pub const ALL: [Section; SECTIONS] = [
        Section::KickDrift,
        Section::BroadSearch,
        Section::Narrow,
        Section::Gather,
        Section::KickChecks,
        Section::SerialInputs,
        Section::SerialGrid,
        Section::SerialStore,
        Section::SerialSums,
    ];

    /// The section's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Section::KickDrift => "kick+drift",
            Section::BroadSearch => "broad search",
            Section::Narrow => "narrow+laws",
            Section::Gather => "gather",
            Section::KickChecks => "kick+checks",
            Section::SerialInputs => "serial: inputs+candidates",
            Section::SerialGrid => "serial: grid build",
            Section::SerialStore => "serial: store sync+rows",
            Section::SerialSums => "serial: sums in order",
        }
    }
}

/// The figures of one section, summed over its runs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SectionStats {
    /// Runs of the section (regions entered, serial sections timed).
    pub runs: u64,
    /// Wall time (from the caller's side: fork to join for a region).
    pub wall: Duration,
    /// CPU time of all threads in the section's work.
    pub cpu: Duration,
    /// Σ over the runs of the busiest thread's CPU time (a serial section: its CPU time).
    pub busiest: Duration,
    /// Σ over the runs of the mean CPU time over the pool's threads (a serial section: its CPU time).
    pub mean: Duration,
    /// Σ over the runs of the costliest chunk's CPU time (a serial section: its CPU time). With chunks
    /// handed out one at a time, the threads of a region end within about one chunk of each other: Σ
    /// costliest / Σ mean bounds the imbalance that the chunking itself causes, whatever the load.
    pub costliest_chunk: Duration,
}

impl SectionStats {
    /// Σ busiest / Σ mean (1 when balanced; 0 when nothing ran).
    pub fn imbalance(&self) -> f64 {
        if self.mean.is_zero() {
            0.0
        } else {
            self.busiest.as_secs_f64() / self.mean.as_secs_f64()
        }
    }
}

static ENABLED: AtomicBool = AtomicBool::new(false);
#[allow(clippy::declare_interior_mutable_const)]
const ZERO: AtomicU64 = AtomicU64::new(0);
/// CPU ns per pool thread in the region being run.
static BUSY: [AtomicU64; MAX_THREADS] = [ZERO; MAX_THREADS];
/// CPU ns of the costliest chunk of the region being run.
static COSTLIEST: AtomicU64 = AtomicU64::new(0);
static STATS: Mutex<[SectionStats; SECTIONS]> = Mutex::new(
    [SectionStats {
        runs: 0,
        wall: Duration::ZERO,
        cpu: Duration::ZERO,
        busiest: Duration::ZERO,
        mean: Duration::ZERO,
        costliest_chunk: Duration::ZERO,
    }; SECTIONS],
);

/// Turns the profile on or off for the whole process.
pub fn enable(on: bool) {
    ENABLED.store(on, Ordering::Relaxed);
}

#[inline]
fn enabled() -> bool {
    ENABLED.load(Ordering::Relaxed)
}

/// The figures gathered since the last call, per section, and clears them.
pub fn take() -> Vec<(Section, SectionStats)> {
    let mut stats = STATS.lock().unwrap_or_else(|e| e.into_inner());
    let out = Section::ALL
        .iter()
        .map(|&s| (s, stats[s as usize]))
        .collect();
    *stats = [SectionStats::default(); SECTIONS];
    out
}

/// CPU time of the calling thread (ns); 0 where the clock is unavailable.
fn thread_cpu_ns() -> u64 {
    crate::host::thread_cpu_ns().unwrap_or(0)
}

/// Runs the parallel region `f` as `section`: the chunks it runs are timed per thread by [`chunk`].
#[inline]
pub fn region<T>(section: Section, f: impl FnOnce() -> T) -> T {
    if !enabled() {
        return f();
    }
    let threads = rayon::current_num_threads().clamp(1, MAX_THREADS);
    for b in &BUSY[..threads] {
        b.store(0, Ordering::Relaxed);
    }
    COSTLIEST.store(0, Ordering::Relaxed);
    let t0 = Instant::now();
    let out = f();
    let wall = t0.elapsed();
    let busy: Vec<u64> = BUSY[..threads]
        .iter()
        .map(|b| b.load(Ordering::Relaxed))
        .collect();
    let total: u64 = busy.iter().sum();
    let busiest = busy.iter().copied().max().unwrap_or(0);
    let mut stats = STATS.lock().unwrap_or_else(|e| e.into_inner());
    let s = &mut stats[section as usize];
    s.runs += 1;
    s.wall += wall;
    s.cpu += Duration::from_nanos(total);
    s.busiest += Duration::from_nanos(busiest);
    s.mean += Duration::from_nanos(total / threads as u64);
    s.costliest_chunk += Duration::from_nanos(COSTLIEST.load(Ordering::Relaxed));
    out
}

/// Runs the serial section `f` as `section` (its CPU time is recorded).
#[inline]
pub fn serial<T>(section: Section, f: impl FnOnce() -> T) -> T {
    let start = serial_start();
    let out = f();
    serial_end(section, start);
    out
}

/// Times one chunk of a region on the calling thread (CPU time, added to its thread's share when
/// dropped). Nothing when the profile is off.
pub struct ChunkTimer(Option<u64>);

/// Starts timing a chunk (see [`ChunkTimer`]).
#[inline]
pub fn chunk() -> ChunkTimer {
    ChunkTimer(enabled().then(thread_cpu_ns))
}

impl Drop for ChunkTimer {
    #[inline]
    fn drop(&mut self) {
        if let Some(c0) = self.0 {
            let k = rayon::current_thread_index()
                .unwrap_or(0)
                .min(MAX_THREADS - 1);
            let cpu = thread_cpu_ns().saturating_sub(c0);
            BUSY[k].fetch_add(cpu, Ordering::Relaxed);
            COSTLIEST.fetch_max(cpu, Ordering::Relaxed);
        }
    }
}

/// Starts a serial section whose end is not in the same closure (see [`serial_end`]).
#[inline]
pub(crate) fn serial_start() -> Option<(u64, Instant)> {
    enabled().then(|| (thread_cpu_ns(), Instant::now()))
}

/// Ends a serial section started by [`serial_start`] (nothing if the profile was off then).
#[inline]
pub(crate) fn serial_end(section: Section, start: Option<(u64, Instant)>) {
    let Some((c0, t0)) = start else {
        return;
    };
    let cpu = Duration::from_nanos(thread_cpu_ns().saturating_sub(c0));
    let wall = t0.elapsed();
    let mut stats = STATS.lock().unwrap_or_else(|e| e.into_inner());
    let s = &mut stats[section as usize];
    s.runs += 1;
    s.wall += wall;
    s.cpu += cpu;
    s.busiest += cpu;
    s.mean += cpu;
    s.costliest_chunk += cpu;
}
