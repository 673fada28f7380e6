//! What the check of the time step (`guard`) may do and what it reports: the choice of a scene, and
//! the findings a step's report or error carries. A leaf file, so that the report and the guard both
//! use it without using each other.

use crate::math::Real;

use super::super::contact_store::ContactKey;

/// What the step does when the check of the time step finds the motion too fast for it (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeStepCheck {
    /// The step fails with [`super::StepError::TimeStep`] (the default: a run whose step no longer resolves
    /// its contacts gives a wrong answer, and nothing in its outputs would say so).
    #[default]
    Stop,
    /// The step goes on and reports the finding in [`super::StepReport::time_step_findings`].
    Warn,
    /// No check (a scene unstable on purpose, e.g. a bisection for the largest stable step).
    Off,
}

/// What the check found in one step.
#[derive(Clone, Debug, PartialEq)]
pub enum TimeStepFinding {
    /// A listed pair meets faster than the largest approach speed the step is stable for.
    FastApproach {
        /// The pair's contact key.
        key: ContactKey,
        /// "body 3 ('a') and body 7 ('b')", or "body 3 ('a') and wall 0 ('floor')".
        pair: String,
        /// Normal speed along the line of centres or the wall normal (m/s; see `fastest_approach`).
        speed: Real,
        /// The largest approach speed for which the step is within the stability limit (m/s).
        critical_speed: Real,
        /// The stability limit at `speed` (s).
        limit: Real,
        /// The step (s).
        dt: Real,
    },
    /// Two bodies (or a body and a wall) can close by more than the smallest particle radius in one step.
    Tunnelling {
        /// The fastest body.
        body: usize,
        /// Its name.
        name: String,
        /// Its speed |v| (m/s).
        speed: Real,
        /// Its move |v| Δt in the step (m).
        displacement: Real,
        /// The bound on how far two bodies, or a body and a wall, close in one step (m).
        closing: Real,
        /// The smallest bounding radius of the scene (m).
        smallest_radius: Real,
    },
}

impl std::fmt::Display for TimeStepFinding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TimeStepFinding::FastApproach {
                pair,
                speed,
                critical_speed,
                limit,
                dt,
                ..
            } => write!(
                f,
                "{pair} meet at a normal speed of {speed:.4e} m/s; the time step {dt:.4e} s is within the stability limit only up to {critical_speed:.4e} m/s (at {speed:.4e} m/s the limit is {limit:.4e} s): the contact will not be resolved (raise simulation.characteristic_speed to the real impact speed, or shorten the step)"
            ),
            TimeStepFinding::Tunnelling {
                body,
                name,
                speed,
                displacement,
                closing,
                smallest_radius,
            } => write!(
                f,
                "body {body} ('{name}') moves {displacement:.4e} m in one step (speed {speed:.4e} m/s); bodies can close by up to {closing:.4e} m in one step, more than the smallest particle radius {smallest_radius:.4e} m: a body can pass into another with no contact tested (shorten the step)"
            ),
        }
    }
}
