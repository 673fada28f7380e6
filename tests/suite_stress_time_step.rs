//! Gate: the quick profile of the validation case `stress_time_step` (the largest stable time step by
//! bisection against the scene's stability limit, linear and Hertz-type laws), through the same rows that
//! `cargo validate` writes to `reports/summary.csv`.
//!
//! Known failures, listed below with their reason, are not asserted (the trajectory is chaotic: any change
//! of the engine's arithmetic moves the individual contact events, and with them whether these rows pass);
//! the gate prints their state, the report shows them as FAIL when they fail, and every other row must pass.

use polydem_validation::gate::assert_quick_case;

/// Rows that failed on the engine of 2026-11-21 (see reports/stress_time_step.md), and why.
const KNOWN_FAILURES: &[(&str, &str)] = &[
    (
        "cube_hertz_k1e8_found_over_theory",
        "Hertz-type law: the largest stable step found is 0.90 of the guard's limit (evaluated at the tangent \
         stiffness of the fall's peak overlap; rocking on vertices reaches deeper overlaps)",
    ),
    (
        "cube_hertz_k1e10_found_over_theory",
        "Hertz-type law, k = 1e10: 0.81 of the guard's limit after the merge of 2026-11-21 (1.03 before; 0.71 in \
         the full profile's longer trials) — same reason",
    ),
    (
        "hull_hertz_k1e8_found_over_theory",
        "Hertz-type law on a random hull: 0.87 of the guard's limit (same reason)",
    ),
];

#[test]
fn stress_time_step_case_quick_profile_passes_every_check_but_the_known_failures() {
    assert_quick_case("stress_time_step", KNOWN_FAILURES);
}
