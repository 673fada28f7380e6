//! The number of steps a run covers, computed with checked arithmetic and held to a limit: an end time
//! far beyond the time step (a huge `end_time`, a tiny `time_step`, or a step derived from a huge stiffness)
//! is refused with the number of steps it implies, instead of saturating the step counter and running
//! forever.
//!
//! The limit is [`DEFAULT_MAX_STEPS`] unless raised explicitly (`simulation.max_steps` in a scene,
//! `--max-steps` on the command line). A run above the range of the step counter (2^64 − 1 steps) is
//! refused whatever the limit.

use crate::math::Real;

/// The longest run accepted without an explicit limit: 10^9 steps. A step of even one sphere costs about a
/// microsecond, so this is about a quarter of an hour of the cheapest run, and days of a run of thousands of
/// bodies; a longer one is far more often a mistaken `end_time` or time step than a wish.
pub const DEFAULT_MAX_STEPS: u64 = 1_000_000_000;

/// Why a run's number of steps was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepCountError {
    /// end_time / Δt does not fit the step counter (or is not a number).
    #[error("end time {end_time:?} s at Δt = {dt:?} s is {steps:e} steps, beyond the step counter's range ({} steps); shorten the end time or lengthen the step", u64::MAX)]
    Overflow {
        /// The end time asked for (s).
        end_time: Real,
        /// The time step (s).
        dt: Real,
        /// end_time / Δt.
        steps: Real,
    },
    /// The run is longer than the limit.
    #[error("end time {end_time:?} s at Δt = {dt:?} s is {steps} steps, above the limit of {limit} steps; raise the limit explicitly (simulation.max_steps in a scene, --max-steps on the command line) to run it")]
    AboveLimit {
        /// The end time asked for (s).
        end_time: Real,
        /// The time step (s).
        dt: Real,
        /// The steps the run would take.
        steps: u64,
        /// The limit in force.
        limit: u64,
    },
}

/// The number of steps of size `dt` that covers `end_time` (at least one; an end time within 1e-9 steps of
/// a whole number of steps is not rounded up by one more), refused above `limit`.
pub fn step_count(end_time: Real, dt: Real, limit: u64) -> Result<u64, StepCountError> {
    let ratio = end_time / dt;
    // `u64::MAX as Real` is 2^64: every f64 below it converts to u64 without saturating.
    if ratio.is_nan() || ratio >= u64::MAX as Real {
        return Err(StepCountError::Overflow {
            end_time,
            dt,
            steps: ratio,
        });
    }
    let steps = (ratio - 1e-9).ceil().max(1.0) as u64;
    if steps > limit {
        return Err(StepCountError::AboveLimit {
            end_time,
            dt,
            steps,
            limit,
        });
    }
    Ok(steps)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_count_rounds_up_and_keeps_whole_numbers() {
        assert_eq!(step_count(1.0, 0.1, DEFAULT_MAX_STEPS), Ok(10));
        assert_eq!(step_count(1.05, 0.1, DEFAULT_MAX_STEPS), Ok(11));
        assert_eq!(step_count(1e-9, 1.0, DEFAULT_MAX_STEPS), Ok(1));
    }

    #[test]
    fn step_count_never_saturates() {
        for (end_time, dt) in [(1e300, 1e-3), (1.0, 1e-300), (1.0, 0.0), (Real::NAN, 1.0)] {
            let got = step_count(end_time, dt, u64::MAX);
            assert!(
                matches!(got, Err(StepCountError::Overflow { .. })),
                "end time {end_time:e}, dt {dt:e}: expected an overflow error, got {got:?}"
            );
        }
    }

    #[test]
    fn step_count_above_the_limit_is_refused_with_the_count() {
        // Δt = 2^-30 s: 2 s is exactly 2^31 steps.
        let dt = (-30.0 as Real).exp2();
        let got = step_count(2.0, dt, DEFAULT_MAX_STEPS);
        assert_eq!(
            got,
            Err(StepCountError::AboveLimit {
                end_time: 2.0,
                dt,
                steps: 1 << 31,
                limit: DEFAULT_MAX_STEPS
            })
        );
        assert_eq!(step_count(2.0, dt, 1 << 31), Ok(1 << 31));
    }
}
