//! Gate: the quick profile of the `precession` validation case — every checked row must
//! pass. The case itself documents the setup and the source of every bound (validation/cases/precession.toml).

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn precession_case_passes_every_check() {
    let report =
        run_case_in_memory("precession", Profile::Quick).expect("precession case is registered");
    assert!(
        report.error.is_none(),
        "precession case failed to complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "precession case produced no checks"
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "precession: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
