//! Gate: the quick profile of the validation case `contact` (GJK/EPA against the exact SAT oracle on the
//! seeded random and degenerate pair sets) must pass every checked row — the same rows that
//! `cargo validate` writes to `reports/summary.csv`, so `cargo test` and the report cannot disagree.

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn contact_case_quick_profile_passes_every_check() {
    let report = run_case_in_memory("contact", Profile::Quick)
        .expect("the contact case's data file must load");
    assert!(
        report.error.is_none(),
        "contact case did not complete: {:?}",
        report.error
    );
    assert!(!report.checks.is_empty(), "contact case produced no checks");
    let failed: Vec<String> = report
        .checks
        .iter()
        .filter(|c| !c.pass)
        .map(|c| {
            format!(
                "{}: measured {:e} {}, target {}",
                c.metric,
                c.value,
                c.unit,
                c.target.render()
            )
        })
        .collect();
    assert!(
        failed.is_empty(),
        "{} of {} contact checks failed (quick profile, inputs: validation/cases/contact.toml):\n{}",
        failed.len(),
        report.checks.len(),
        failed.join("\n")
    );
}
