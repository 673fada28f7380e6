//! Gate: the quick profile of the validation case `stress_shapes` (slivers of 20:1, a mass ratio of 1:10^4,
//! pairs released from overlaps of up to half a particle: no step error, statuses equal to the exact SAT
//! oracle, no tunnelling, energy error bounded), through the same rows that `cargo validate` writes to
//! `reports/summary.csv`.
//!
//! Known failures, listed below with their reason, are not asserted (the trajectory is chaotic: any change
//! of the engine's arithmetic moves the individual contact events, and with them whether these rows pass);
//! the gate prints their state, the report shows them as FAIL when they fail, and every other row must pass.

use polydem_validation::gate::assert_quick_case;

/// Rows not asserted, and why: none. Both former entries pass: `mass_ratio_energy_error_max`
/// (6.1e-3 against 1e-2 since the wall and pair bands follow the rule of `polydem::contact::wall_depth`) and
/// `overlap_0.25_energy_error_max` (6.2e-5 against 1e-3 since the release runs' pair smoothing band does too;
/// with the default band it read 1.56e-3, a one-step blip proportional to Δt: the report's band sweep).
const KNOWN_FAILURES: &[(&str, &str)] = &[];

#[test]
fn stress_shapes_case_quick_profile_passes_every_check_but_the_known_failures() {
    assert_quick_case("stress_shapes", KNOWN_FAILURES);
}
