//! Gate: the quick profile of the validation case `stress_time_step` (the largest stable time step by
//! bisection against the scene's stability limit, linear and Hertz-type laws), through the same rows that
//! `cargo validate` writes to `reports/summary.csv`.
//!
//! Known failures, listed below with their reason, are not asserted (the trajectory is chaotic: any change
//! of the engine's arithmetic moves the individual contact events, and with them whether these rows pass);
//! the gate prints their state, the report shows them as FAIL when they fail, and every other row must pass.

use polydem_validation::gate::assert_quick_case;

/// Rows that fail on the current engine, and why (none: the three Hertz-type rows, 0.81–0.87 of the former
/// limit 2/ω, pass since the guard includes the overshoot factor f(n) of `src/scene/time_step.rs`).
const KNOWN_FAILURES: &[(&str, &str)] = &[];

#[test]
fn stress_time_step_case_quick_profile_passes_every_check_but_the_known_failures() {
    assert_quick_case("stress_time_step", KNOWN_FAILURES);
}
