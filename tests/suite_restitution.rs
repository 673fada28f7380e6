//! Gate: the quick profile of the `restitution` validation case — every checked row must
//! pass. The case itself documents the setup and the source of every bound (validation/cases/restitution.toml).

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn restitution_case_passes_every_check() {
    let report =
        run_case_in_memory("restitution", Profile::Quick).expect("restitution case is registered");
    assert!(
        report.error.is_none(),
        "restitution case failed to complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "restitution case produced no checks"
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "restitution: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
