//! Gate: the quick profile of the `single_contact_energy` validation case — every checked row must
//! pass. The case itself documents the setup and the source of every bound (validation/cases/single_contact_energy.toml).

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn single_contact_energy_case_passes_every_check() {
    let report = run_case_in_memory("single_contact_energy", Profile::Quick)
        .expect("single_contact_energy case is registered");
    assert!(
        report.error.is_none(),
        "single_contact_energy case failed to complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "single_contact_energy case produced no checks"
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "single_contact_energy: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
