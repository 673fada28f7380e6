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
    /// Runs all steps. `on_output` is called at the start and every `output_every` steps (and after the last
    /// step if it is not an output step); `on_step` after every step with the number of steps done.
    pub fn run(
        &mut self,
        mut on_output: impl FnMut(&Simulation) -> std::io::Result<()>,
        mut on_step: impl FnMut(u64),
    ) -> Result<RunSummary, RunError> {
        let start = Instant::now();
        let mut scratch = StepScratch::default();
        let mut summary = RunSummary::default();
        on_output(self)?;
        for n in 1..=self.steps {
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
            on_step(n);
        }
        summary.steps = self.steps;
        summary.wall_time = start.elapsed();
        Ok(summary)
    }
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
