//! Running a [`Simulation`] to its end time: the step loop, with output at fixed step intervals handed to
//! an observer (the step itself never writes anything).

use std::time::{Duration, Instant};

use crate::math::Real;
use crate::world::{step, StepCounters, StepError, StepScratch};

use super::Simulation;

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Step(#[from] StepError),
    #[error("writing output: {0}")]
    Output(#[from] std::io::Error),
}

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct RunSummary {
    pub steps: u64,
    pub wall_time: Duration,
    pub counters: StepCounters,
    /// Largest overlap / particle size seen at the end of any step.
    pub max_overlap_ratio: Real,
    /// Steps that reported a contact deeper than the warning fraction, and the first such step.
    pub steps_with_deep_overlap: u64,
    pub first_deep_overlap_step: Option<u64>,
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
        let first = self.world.step_index + 1;
        on_output(self)?;
        for n in first..=self.steps {
            let report = step(&self.params, &mut self.world, &mut scratch)?;
            summary.counters.merge(&report.counters);
            summary.max_overlap_ratio = summary.max_overlap_ratio.max(report.max_overlap_ratio);
            if !report.overlap_warnings.is_empty() {
                summary.steps_with_deep_overlap += 1;
                summary
                    .first_deep_overlap_step
                    .get_or_insert(self.world.step_index);
            }
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
    /// Moves the end of the run to `end_time` (s), e.g. to continue a restored checkpoint further: the run
    /// then covers ⌈end_time / Δt⌉ steps in total (counted from step 0, as the scene's own end time is).
    pub fn set_end_time(&mut self, end_time: Real) -> Result<(), EndTimeError> {
        let dt = self.params.dt;
        if !(end_time.is_finite() && end_time > 0.0) {
            return Err(EndTimeError::NotPositive { end_time });
        }
        let steps = steps_to(end_time, dt);
        if steps < self.world.step_index {
            return Err(EndTimeError::BeforeNow {
                end_time,
                time: self.world.time,
                step: self.world.step_index,
            });
        }
        self.end_time = end_time;
        self.steps = steps;
        Ok(())
    }
}

/// The number of steps of size `dt` that covers `end_time` (at least one; an end time within 1e-9 steps
/// of a whole number of steps is not rounded up by one more).
pub(crate) fn steps_to(end_time: Real, dt: Real) -> u64 {
    (end_time / dt - 1e-9).ceil().max(1.0) as u64
}

/// Why an end time was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EndTimeError {
    #[error("end time {end_time} s must be finite and positive")]
    NotPositive { end_time: Real },
    #[error("end time {end_time} s lies before the current time {time} s (step {step})")]
    BeforeNow {
        end_time: Real,
        time: Real,
        step: u64,
    },
}

impl std::fmt::Display for RunSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "steps {}, wall time {:.3} s",
            self.steps,
            self.wall_time.as_secs_f64()
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
        write!(f, "{}", self.counters)
    }
}
