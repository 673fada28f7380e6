//! The stage timers and counters of the step.

use std::time::Duration;

use crate::contact::QueryCounters;

use super::super::timing::{Stage, StageTime};

#[cfg(doc)]
use super::super::parallel::Parallelism;

/// Stage timers and counters of one or more steps (merge them with [`StepCounters::merge`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepCounters {
    /// Steps counted.
    pub steps: u64,
    /// Wall time of the broad phase.
    pub broad: Duration,
    /// The fused narrow phase and laws (one pass over the candidates).
    pub narrow: Duration,
    /// Zero since the laws run fused with the narrow phase (their time is in `narrow`); kept so that the
    /// summaries keep their columns.
    pub laws: Duration,
    /// Wall time of the per-body force and torque sums.
    pub accumulate: Duration,
    /// Stages 1–2 and 7–8 (the checks run fused with the second half kick).
    pub integrate: Duration,
    /// Zero since the checks run fused with the second half kick (their time is in `integrate`); kept so
    /// that the summaries keep their columns.
    pub checks: Duration,
    /// The part of the stage times spent in sections that run on one thread whatever the pool: the
    /// bookkeeping around the parallel regions (per-body inputs, candidate list, store sync, grid build,
    /// sums in candidate order) and every region that stays below its [`Parallelism`] threshold. On one
    /// thread, `serial / total_time()` is the serial fraction of Amdahl's law for that scene (the
    /// single-thread scatter of the forces counts here, the gather that replaces it on several threads
    /// does not: a slight overestimate).
    pub serial: Duration,
    /// Broad-phase grid rebuilds.
    pub broad_rebuilds: u64,
    /// Body pairs passed to the narrow phase (broad-phase candidates with at least one dynamic body).
    pub body_pairs_tested: u64,
    /// Body–wall pairs passed to the narrow phase.
    pub wall_pairs_tested: u64,
    /// Body–wall pairs rejected by the bounding-sphere distance.
    pub wall_pairs_rejected: u64,
    /// Overlapping contacts evaluated by the laws.
    pub contacts: u64,
    /// Contact-store entries created.
    pub contacts_created: u64,
    /// Contact-store entries dropped.
    pub contacts_dropped: u64,
    /// Candidates not re-evaluated because frozen (both sides asleep or fixed; see [`crate::world::sleeping`]).
    pub frozen_pairs: u64,
    /// Bodies that fell asleep.
    pub fell_asleep: u64,
    /// Bodies woken.
    pub woken: u64,
    /// Sleeping bodies summed over the steps (body-steps).
    pub sleeping_body_steps: u64,
    /// Bodies that moved more than half the skin in one step, summed over the steps ("dangerous builds";
    /// see `world::step::guard`).
    pub dangerous_moves: u64,
    /// Narrow-phase counters (queries by kind, GJK/EPA iterations, fallbacks).
    pub query: QueryCounters,
}

impl StepCounters {
    /// Adds the counts and times of `other` (e.g. of a later stretch of steps) to `self`.
    pub fn merge(&mut self, other: &StepCounters) {
        self.steps += other.steps;
        self.broad += other.broad;
        self.narrow += other.narrow;
        self.laws += other.laws;
        self.accumulate += other.accumulate;
        self.integrate += other.integrate;
        self.checks += other.checks;
        self.serial += other.serial;
        self.broad_rebuilds += other.broad_rebuilds;
        self.body_pairs_tested += other.body_pairs_tested;
        self.wall_pairs_tested += other.wall_pairs_tested;
        self.wall_pairs_rejected += other.wall_pairs_rejected;
        self.contacts += other.contacts;
        self.contacts_created += other.contacts_created;
        self.contacts_dropped += other.contacts_dropped;
        self.frozen_pairs += other.frozen_pairs;
        self.fell_asleep += other.fell_asleep;
        self.woken += other.woken;
        self.sleeping_body_steps += other.sleeping_body_steps;
        self.dangerous_moves += other.dangerous_moves;
        self.query.merge(&other.query);
    }

    /// Adds the time of `stage` (see [`crate::world::timing`]).
    #[inline]
    pub fn add(&mut self, stage: Stage, time: StageTime) {
        let slot = match stage {
            Stage::Broad => &mut self.broad,
            Stage::Narrow => &mut self.narrow,
            Stage::Accumulate => &mut self.accumulate,
            Stage::Integrate => &mut self.integrate,
        };
        *slot += time.wall;
        self.serial += time.serial;
    }

    /// Wall time of all stages.
    pub fn total_time(&self) -> Duration {
        self.broad + self.narrow + self.laws + self.accumulate + self.integrate + self.checks
    }
}

impl std::fmt::Display for StepCounters {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        writeln!(
            f,
            "stage times (ms): broad {:.1}, narrow {:.1}, laws {:.1}, accumulate {:.1}, integrate {:.1}, checks {:.1}; on one thread whatever the pool {:.1}",
            ms(self.broad),
            ms(self.narrow),
            ms(self.laws),
            ms(self.accumulate),
            ms(self.integrate),
            ms(self.checks),
            ms(self.serial)
        )?;
        writeln!(
            f,
            "steps {}, broad-phase rebuilds {}, body pairs tested {}, wall pairs tested {} (rejected by distance {}), contacts {}, store entries created {} dropped {}",
            self.steps,
            self.broad_rebuilds,
            self.body_pairs_tested,
            self.wall_pairs_tested,
            self.wall_pairs_rejected,
            self.contacts,
            self.contacts_created,
            self.contacts_dropped
        )?;
        if self.frozen_pairs + self.fell_asleep + self.sleeping_body_steps > 0 {
            writeln!(
                f,
                "sleeping: frozen pairs {}, bodies fell asleep {}, woken {}, sleeping body-steps {}",
                self.frozen_pairs, self.fell_asleep, self.woken, self.sleeping_body_steps
            )?;
        }
        if self.dangerous_moves > 0 {
            writeln!(
                f,
                "bodies that moved more than half the skin in one step (body-steps): {}",
                self.dangerous_moves
            )?;
        }
        write!(f, "{}", self.query)
    }
}
