//! A run of many steps ([`SphereSim::run_steps`]): on several threads, the pool's threads held for the
//! whole run ([`super::crew`]) instead of called up for each step.

use std::ops::ControlFlow;

use super::super::step::{StepError, StepReport};
use super::crew::Crew;
use super::SphereSim;

impl SphereSim {
    /// Runs up to `steps` steps and calls `after_step` with the simulation and the step's report after
    /// each; stops after the step for which it returns [`ControlFlow::Break`], or at a step's error.
    /// Returns the number of steps run.
    ///
    /// The same bits as [`step`](Self::step) called as often. On a pool of several threads (and a
    /// simulation large enough for its parallel passes) the run holds the pool's threads from the
    /// first step to the last, each step's team job handed to threads already running: `after_step`
    /// runs on one of them (hence `Send`), and no other work of the pool's gets a thread until the run
    /// ends but through their idle polling (see `crew`).
    pub fn run_steps(
        &mut self,
        steps: u64,
        mut after_step: impl FnMut(&SphereSim, &StepReport) -> ControlFlow<()> + Send,
    ) -> Result<u64, StepError> {
        let mut lead = |sim: &mut SphereSim, crew: Option<&Crew>| -> Result<u64, StepError> {
            for done in 1..=steps {
                let report = sim.step_on(crew)?;
                if after_step(sim, &report).is_break() {
                    return Ok(done);
                }
            }
            Ok(steps)
        };
        if steps > 1 && self.parallel_bodies() {
            Crew::hold(|crew| lead(self, Some(crew)))
        } else {
            lead(self, None)
        }
    }
}
