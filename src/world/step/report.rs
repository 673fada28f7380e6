//! What a step observed, and why a step failed.

use crate::contact::ContactError;
use crate::math::Real;

use super::super::contact_store::ContactKey;
use super::super::world::World;
use super::counters::StepCounters;
use super::guard::TimeStepFinding;

/// A contact deeper than the warning fraction of the particle size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlapWarning {
    pub key: ContactKey,
    /// Overlap δ_M (m).
    pub depth: Real,
    /// δ_M divided by the smaller particle's length scale.
    pub ratio: Real,
}

/// What one step observed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepReport {
    pub counters: StepCounters,
    /// Overlapping contacts at the end of the step.
    pub contacts: usize,
    /// The largest overlap / particle size at the end of the step.
    pub max_overlap_ratio: Real,
    pub overlap_warnings: Vec<OverlapWarning>,
    /// What the check of the time step found in this step, when it warns instead of stopping (see
    /// [`super::guard`]).
    pub time_step_findings: Vec<TimeStepFinding>,
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    #[error("step {step}: body {body} ('{name}') has a non-finite {quantity}")]
    NonFinite {
        step: u64,
        body: usize,
        name: String,
        quantity: &'static str,
    },
    #[error("step {step}: invalid time step {dt} s (must be finite and positive)")]
    InvalidTimeStep { step: u64, dt: Real },
    #[error("step {step}: contact query failed: {source}")]
    Contact {
        step: u64,
        #[source]
        source: ContactError,
    },
    #[error("step {step}: no contact law for materials {a} and {b}")]
    MissingLaw { step: u64, a: u32, b: u32 },
    #[error("step {step}: {finding} [time-step check; simulation.time_step_check = \"warn\" reports and goes on, \"off\" skips it]")]
    TimeStep {
        step: u64,
        finding: Box<TimeStepFinding>,
    },
}

impl StepError {
    /// The error for the first body with a non-finite `quantity` found by the checks of stages 7–8, in
    /// the step being taken.
    pub(super) fn non_finite(world: &World, (body, quantity): (usize, &'static str)) -> Self {
        StepError::NonFinite {
            step: world.step_index + 1,
            body,
            name: world.names[body].clone(),
            quantity,
        }
    }
}
