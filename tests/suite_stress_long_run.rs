//! Gate: the quick profile of the validation case `stress_long_run` (an elastic, frictionless closed box of
//! spinning polyhedra; energy bounded with no drift trend), through the same rows that `cargo validate`
//! writes to `reports/summary.csv`.
//!
//! Known failures, listed below with their reason, are not asserted (the trajectory is chaotic: any change
//! of the engine's arithmetic moves the individual contact events, and with them whether these rows pass);
//! the gate prints their state, the report shows them as FAIL when they fail, and every other row must pass.

use polydem_validation::gate::assert_quick_case;

/// Rows that failed on an earlier engine (see reports/stress_long_run.md), and why. Both pass in the
/// current report (7.8e-4 against 1e-3, 0.29 against 1), on one trajectory of a mechanism that does not
/// shrink with Δt, so they stay unasserted: a change of arithmetic can move them back over the bound.
const KNOWN_FAILURES: &[(&str, &str)] = &[
    (
        "slabs_energy_error_max",
        "single jumps of ~2e-3 E0 in the polyhedron–polyhedron box that did not shrink with Δt \
         (3.4e-3 at t_c/200, 2.8e-3 at t_c/400 on one trajectory): a discontinuity of the contact \
         potential, not integration error; other trajectories stay below 1e-3",
    ),
    (
        "slabs_drift_fitted_change_over_scatter",
        "per-event energy errors accumulate like a random walk: over a short run the fitted line's change \
         is of the order of the scatter (1.4 and 4.8 on two trajectories)",
    ),
];

#[test]
fn stress_long_run_case_quick_profile_passes_every_check_but_the_known_failures() {
    assert_quick_case("stress_long_run", KNOWN_FAILURES);
}
