//! Gate: the quick profile of the `ellipsoid_impact` validation case — every checked row must pass. The case
//! itself documents the setup and the source of every bound (validation/cases/ellipsoid_impact.toml).

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn ellipsoid_impact_case_passes_every_check() {
    let report = run_case_in_memory("ellipsoid_impact", Profile::Quick)
        .expect("ellipsoid_impact case is registered");
    assert!(
        report.error.is_none(),
        "ellipsoid_impact case failed to complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "ellipsoid_impact case produced no checks"
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "ellipsoid_impact: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
