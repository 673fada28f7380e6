//! Gate: the quick profile of the `chung_ooi` validation case — every checked row must
//! pass. The case itself documents the setup and the source of every bound (validation/cases/chung_ooi.toml).

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn chung_ooi_case_passes_every_check() {
    let report =
        run_case_in_memory("chung_ooi", Profile::Quick).expect("chung_ooi case is registered");
    assert!(
        report.error.is_none(),
        "chung_ooi case failed to complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "chung_ooi case produced no checks"
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "chung_ooi: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
