//! Gate: the quick profile of the `rockfill` validation case — every checked row must pass, the time-step
//! convergence rows included. The case documents the setup and the source of every bound
//! (validation/cases/rockfill.toml).

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn rockfill_case_passes_every_check() {
    let report =
        run_case_in_memory("rockfill", Profile::Quick).expect("rockfill case is registered");
    assert!(
        report.error.is_none(),
        "rockfill case failed to complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "rockfill case produced no checks"
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "rockfill: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
