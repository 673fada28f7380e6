//! What a step observed, and why a step failed.

use crate::contact::ContactError;
use crate::math::Real;

use super::super::contact_store::ContactKey;
use super::super::world::World;
use super::counters::StepCounters;
use super::findings::TimeStepFinding;

/// A contact deeper than the warning fraction of the particle size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlapWarning {
    /// The contact.
    pub key: ContactKey,
    /// Overlap δ_M (m).
    pub depth: Real,
    /// δ_M divided by the smaller particle's length scale.
    pub ratio: Real,
}

/// What one step observed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Stage timers and counters of the step.
    pub counters: StepCounters,
    /// Overlapping contacts at the end of the step.
    pub contacts: usize,
    /// The largest overlap / particle size at the end of the step.
    pub max_overlap_ratio: Real,
    /// Contacts deeper than the warning fraction.
    pub overlap_warnings: Vec<OverlapWarning>,
    /// What the check of the time step found in this step, when it warns instead of stopping (see
    /// `world::step::guard`).
    pub time_step_findings: Vec<TimeStepFinding>,
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// A body's state became NaN or infinite.
    #[error("step {step}: body {body} ('{name}') has a non-finite {quantity}")]
    NonFinite {
        /// The step being taken.
        step: u64,
        /// Index of the body.
        body: usize,
        /// Name of the body.
        name: String,
        /// Which quantity (e.g. position, velocity).
        quantity: &'static str,
    },
    /// The time step is not finite and positive.
    #[error("step {step}: invalid time step {dt} s (must be finite and positive)")]
    InvalidTimeStep {
        /// The step being taken.
        step: u64,
        /// The time step given (s).
        dt: Real,
    },
    /// A contact query failed.
    #[error("step {step}: contact query failed: {source}")]
    Contact {
        /// The step being taken.
        step: u64,
        /// The query's error.
        #[source]
        source: ContactError,
    },
    /// Two materials met that have no contact law.
    #[error("step {step}: no contact law for materials {a} and {b}")]
    MissingLaw {
        /// The step being taken.
        step: u64,
        /// First material id.
        a: u32,
        /// Second material id.
        b: u32,
    },
    /// The runtime time-step check found a pair (or a body) the step does not resolve.
    #[error("step {step}: {finding} [time-step check; simulation.time_step_check = \"warn\" reports and goes on, \"off\" skips it]")]
    TimeStep {
        /// The step being taken.
        step: u64,
        /// What the check found.
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
