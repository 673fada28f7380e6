//! How the step times its stages: one [`StageClock`] per stage, started when the stage starts and stopped
//! into the step's counters ([`super::StepCounters::add`]) when it ends.
//!
//! A stage's time has two parts: its wall time, and the part of it that runs on one thread whatever the
//! pool (the *serial* part: the bookkeeping around the parallel regions, and every region that stays below
//! its [`super::Parallelism`] threshold). The clock learns which regions are parallel from the stage
//! ([`StageClock::region`]); on one thread, serial time over total time is then the serial fraction of
//! Amdahl's law for the scene. The same calls feed the opt-in per-thread profile of
//! [`super::region_profile`] (its sections and chunks), so a stage is timed in one place.

use std::time::{Duration, Instant};

use super::region_profile::{self, Section};

/// The stages the counters time (the fields of [`super::StepCounters`] of the same names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Stage 3.
    Broad,
    /// Stages 4–5, fused.
    Narrow,
    /// Stage 6.
    Accumulate,
    /// Stages 1–2 and 7–8 (the checks run fused with the second half kick).
    Integrate,
}

/// The time of one stage: its wall time and the part of it that ran on one thread whatever the pool.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTime {
    /// Wall time of the stage.
    pub wall: Duration,
    /// Part of `wall` spent on one thread whatever the pool.
    pub serial: Duration,
}

/// The clock of one stage (see the module docs).
#[derive(Debug)]
pub struct StageClock {
    start: Instant,
    /// Wall time of the stage's regions that run on the pool.
    on_pool: Duration,
}

impl StageClock {
    /// Starts the clock of a stage.
    #[inline]
    pub fn start() -> Self {
        Self {
            start: Instant::now(),
            on_pool: Duration::ZERO,
        }
    }

    /// Runs the region `f` as `section` of the profile; `on_pool` says whether it is parallel (large
    /// enough for the pool: its time is then not serial, whatever the pool's size).
    #[inline]
    pub fn region<T>(&mut self, section: Section, on_pool: bool, f: impl FnOnce() -> T) -> T {
        self.pool(on_pool, || region_profile::region(section, f))
    }

    /// Runs `f`, whose time is not serial when `on_pool` (a parallel pass outside the profile's sections).
    #[inline]
    pub fn pool<T>(&mut self, on_pool: bool, f: impl FnOnce() -> T) -> T {
        if !on_pool {
            return f();
        }
        let t = Instant::now();
        let out = f();
        self.on_pool += t.elapsed();
        out
    }

    /// Runs the serial section `f` as `section` of the profile (its time stays serial).
    #[inline]
    pub fn serial<T>(&mut self, section: Section, f: impl FnOnce() -> T) -> T {
        region_profile::serial(section, f)
    }

    /// Starts a serial section of the profile whose end is not in the same closure.
    #[inline]
    pub(crate) fn serial_start(&self) -> Option<(u64, Instant)> {
        region_profile::serial_start()
    }

    /// Ends a serial section started by [`StageClock::serial_start`].
    #[inline]
    pub(crate) fn serial_end(&self, section: Section, start: Option<(u64, Instant)>) {
        region_profile::serial_end(section, start)
    }

    /// The stage's time so far.
    #[inline]
    pub fn stop(self) -> StageTime {
        let wall = self.start.elapsed();
        StageTime {
            wall,
            serial: wall.saturating_sub(self.on_pool),
        }
    }
}
