//! Gate: the quick profile of the `friction` validation case — every checked row must
//! pass. The case itself documents the setup and the source of every bound (validation/cases/friction.toml).

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn friction_case_passes_every_check() {
    let report =
        run_case_in_memory("friction", Profile::Quick).expect("friction case is registered");
    assert!(
        report.error.is_none(),
        "friction case failed to complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "friction case produced no checks"
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "friction: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
