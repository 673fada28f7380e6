//! Running a [`Simulation`] to its end time: the step loop, with output at fixed step intervals handed to
//! an observer (the step itself never writes anything).
//!
//! Two forms: [`Simulation::run`] hands the simulation to a closure after every step, so it keeps the
//! world current and takes the general step; [`Simulation::run_observed`] asks a [`RunObserver`] at which
//! steps it reads the state, and between those the pipeline chooses how to step. A world of free spheres
//! (every body a dynamic sphere of equal principal moments, no sleeping, no global damping; the energy
//! ledger on or off) then runs on the flat sphere layout ([`SphereSim`]: struct-of-arrays, half
//! neighbour lists, the thread team), the same bits as the general step — bodies, loads and ledger —
//! written back into the world wherever the observer reads it.

use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use crate::math::Real;
use crate::world::{
    step, SphereSim, StepCounters, StepError, StepFlatError, StepReport, StepScratch,
};

use super::run_length::{step_count, StepCountError, DEFAULT_MAX_STEPS};
use super::simulation::Simulation;

/// What a run hands the state to: outputs, frames, checkpoints, progress.
pub trait RunObserver {
    /// Whether the observer reads the state after step `step` (counted from step 0). The run keeps the
    /// world current at these steps only.
    fn wants_state(&self, step: u64) -> bool;
    /// Called with the simulation after each step `step` for which [`Self::wants_state`] holds, and at
    /// the start with the step the run starts from.
    fn observe(&mut self, sim: &Simulation, step: u64) -> std::io::Result<()>;
    /// Called with the number of steps done (from step 0) at least every [`PROGRESS_STEPS`] steps and
    /// at every observed step; it sees no state.
    fn progress(&mut self, _step: u64) {}
    /// Whether the observer reads the contact store or the broad phase at step `step` (a checkpoint
    /// does; CSV rows and VTK frames do not). Where it does not, the pipeline may hand it a world whose
    /// bodies, walls, loads, ledger and time are current but whose contact store and broad phase are
    /// those of an earlier step.
    fn reads_contacts(&self, _step: u64) -> bool {
        true
    }
}

/// The longest stretch of steps between two calls of [`RunObserver::progress`].
pub const PROGRESS_STEPS: u64 = 64;

/// How a run was stepped.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum StepPath {
    /// The general step ([`crate::world::step()`]).
    #[default]
    General,
    /// The flat sphere layout ([`SphereSim`]).
    FlatSpheres,
}

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
    /// Writing an output file failed.
    #[error("writing output: {0}")]
    Output(#[from] std::io::Error),
}

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct RunSummary {
    /// Steps taken.
    pub steps: u64,
    /// Wall time of the run loop.
    pub wall_time: Duration,
    /// Counters and stage times of the steps.
    pub counters: StepCounters,
    /// Largest overlap / particle size seen at the end of any step.
    pub max_overlap_ratio: Real,
    /// Steps that reported a contact deeper than the warning fraction.
    pub steps_with_deep_overlap: u64,
    /// The first step that reported a contact deeper than the warning fraction.
    pub first_deep_overlap_step: Option<u64>,
    /// Steps in which the check of the time step found the motion too fast for it (with
    /// `time_step_check = "warn"`), and the first finding with its step.
    pub steps_with_time_step_findings: u64,
    /// The first finding of the time-step check: its step and its message.
    pub first_time_step_finding: Option<(u64, String)>,
    /// The path the steps took.
    pub path: StepPath,
}

impl RunSummary {
    /// Books one step's report (the world's step index after it is `step_index`).
    fn add(&mut self, report: &StepReport, step_index: u64) {
        self.counters.merge(&report.counters);
        self.max_overlap_ratio = self.max_overlap_ratio.max(report.max_overlap_ratio);
        if !report.overlap_warnings.is_empty() {
            self.steps_with_deep_overlap += 1;
            self.first_deep_overlap_step.get_or_insert(step_index);
        }
        if let Some(finding) = report.time_step_findings.first() {
            self.steps_with_time_step_findings += 1;
            self.first_time_step_finding
                .get_or_insert_with(|| (step_index, finding.to_string()));
        }
    }
}

impl Simulation {
    /// Runs the remaining steps: from the world's step count (0 for a fresh scene, more for one restored
    /// from a checkpoint) to `steps`. `on_output` is called at the start and every `output_every` steps
    /// counted from step 0 (and after the last step if it is not an output step); `on_step` after every
    /// step with the simulation and the number of steps done since step 0 (it may write frames or
    /// checkpoints; its error stops the run).
    pub fn run(
        &mut self,
        mut on_output: impl FnMut(&Simulation) -> std::io::Result<()>,
        mut on_step: impl FnMut(&Simulation, u64) -> std::io::Result<()>,
    ) -> Result<RunSummary, RunError> {
        let start = Instant::now();
        let mut scratch = StepScratch::default();
        let mut summary = RunSummary::default();
        let first = self.world.step_index() + 1;
        on_output(self)?;
        for n in first..=self.steps {
            let report = step(&self.params, &mut self.world, &mut scratch)?;
            summary.add(&report, self.world.step_index());
            if n % self.output_every == 0 || n == self.steps {
                on_output(self)?;
            }
            on_step(self, n)?;
        }
        summary.steps = (self.steps + 1).saturating_sub(first);
        summary.wall_time = start.elapsed();
        Ok(summary)
    }
}

impl Simulation {
    /// Runs the remaining steps (as [`Self::run`]) and hands the state to `observer` at the steps it
    /// asks for; the pipeline chooses how to step in between (see the module docs). The result is the
    /// same bits as [`Self::run`] whichever path runs.
    pub fn run_observed(
        &mut self,
        observer: &mut impl RunObserver,
    ) -> Result<RunSummary, RunError> {
        let start = Instant::now();
        let first = self.world.step_index();
        observer.observe(self, first)?;
        observer.progress(first);
        let mut summary = match SphereSim::from_world(&self.world, &self.params) {
            Ok(flat) => self.run_flat(flat, observer)?,
            Err(StepFlatError::NotSphereOnly(_)) => self.run_general(observer)?,
            Err(StepFlatError::Step(e)) => return Err(e.into()),
        };
        summary.steps = self.world.step_index() - first;
        summary.wall_time = start.elapsed();
        Ok(summary)
    }

    /// The step after `done` up to which a stretch runs: the next step the observer reads, at most
    /// [`PROGRESS_STEPS`] on, at most the last.
    fn stretch_end(&self, done: u64, observer: &impl RunObserver) -> u64 {
        let last = self.steps.min(done + PROGRESS_STEPS);
        (done + 1..last)
            .find(|&n| observer.wants_state(n))
            .unwrap_or(last)
    }

    fn run_general(&mut self, observer: &mut impl RunObserver) -> Result<RunSummary, RunError> {
        let mut scratch = StepScratch::default();
        let mut summary = RunSummary::default();
        while self.world.step_index() < self.steps {
            let end = self.stretch_end(self.world.step_index(), observer);
            while self.world.step_index() < end {
                let report = step(&self.params, &mut self.world, &mut scratch)?;
                summary.add(&report, self.world.step_index());
            }
            self.after_stretch(observer, end)?;
        }
        Ok(summary)
    }

    fn run_flat(
        &mut self,
        mut flat: SphereSim,
        observer: &mut impl RunObserver,
    ) -> Result<RunSummary, RunError> {
        let mut summary = RunSummary {
            path: StepPath::FlatSpheres,
            ..RunSummary::default()
        };
        while flat.step_index() < self.steps {
            let end = self.stretch_end(flat.step_index(), observer);
            let wanted = end - flat.step_index();
            let done = flat.run_steps(wanted, |sim, report| {
                summary.add(report, sim.step_index());
                ControlFlow::Continue(())
            })?;
            debug_assert_eq!(done, wanted);
            if end == self.steps || observer.wants_state(end) && observer.reads_contacts(end) {
                flat.write_back(&mut self.world);
            } else if observer.wants_state(end) {
                flat.write_back_bodies(&mut self.world);
            }
            self.after_stretch(observer, end)?;
        }
        Ok(summary)
    }

    fn after_stretch(&self, observer: &mut impl RunObserver, end: u64) -> Result<(), RunError> {
        if observer.wants_state(end) || end == self.steps {
            observer.observe(self, end)?;
        }
        observer.progress(end);
        Ok(())
    }

    /// Moves the end of the run to `end_time` (s), e.g. to continue a restored checkpoint further: the run
    /// then covers ⌈end_time / Δt⌉ steps in total (counted from step 0, as the scene's own end time is),
    /// at most [`DEFAULT_MAX_STEPS`] (see [`Self::set_end_time_within`]).
    pub fn set_end_time(&mut self, end_time: Real) -> Result<(), EndTimeError> {
        self.set_end_time_within(end_time, DEFAULT_MAX_STEPS)
    }

    /// [`Self::set_end_time`] with the limit `max_steps` on the run's total number of steps.
    pub fn set_end_time_within(
        &mut self,
        end_time: Real,
        max_steps: u64,
    ) -> Result<(), EndTimeError> {
        let dt = self.params.dt;
        if !(end_time.is_finite() && end_time > 0.0) {
            return Err(EndTimeError::NotPositive { end_time });
        }
        let steps = step_count(end_time, dt, max_steps)?;
        if steps < self.world.step_index() {
            return Err(EndTimeError::BeforeNow {
                end_time,
                time: self.world.time(),
                step: self.world.step_index(),
            });
        }
        self.end_time = end_time;
        self.steps = steps;
        Ok(())
    }
}

/// Why an end time was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EndTimeError {
    /// The end time is not finite and positive.
    #[error("end time {end_time} s must be finite and positive")]
    NotPositive {
        /// The end time asked for (s).
        end_time: Real,
    },
    /// The end time lies before the simulation's current time.
    #[error("end time {end_time} s lies before the current time {time} s (step {step})")]
    BeforeNow {
        /// The end time asked for (s).
        end_time: Real,
        /// The current simulated time (s).
        time: Real,
        /// The current step.
        step: u64,
    },
    /// The end time gives a step count beyond the counter or the run's limit.
    #[error(transparent)]
    Steps(#[from] StepCountError),
}

impl std::fmt::Display for RunSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "steps {}, wall time {:.3} s, {}",
            self.steps,
            self.wall_time.as_secs_f64(),
            match self.path {
                StepPath::General => "general step",
                StepPath::FlatSpheres => "flat sphere layout",
            }
        )?;
        writeln!(
            f,
            "largest overlap / particle size {:.3e}; steps with an overlap above the warning fraction: {}{}",
            self.max_overlap_ratio,
            self.steps_with_deep_overlap,
            self.first_deep_overlap_step
                .map(|s| format!(" (first at step {s})"))
                .unwrap_or_default()
        )?;
        if let Some((step, finding)) = &self.first_time_step_finding {
            writeln!(
                f,
                "time-step check: {} steps found the motion too fast for the step; first at step {step}: {finding}",
                self.steps_with_time_step_findings
            )?;
        }
        write!(f, "{}", self.counters)
    }
}
