//! Gate: the quick profile of the validation case `stress_impact` (a polyhedron at 1200 m/s into a bed and
//! onto a wall: no step error, no tunnelling or pass-through, the time-step guard refusing a step above the
//! stability limit, the tunnelling detector firing when the guard is bypassed) must pass every checked row —
//! the same rows that `cargo validate` writes to `reports/summary.csv`.

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn stress_impact_case_quick_profile_passes_every_check() {
    let report = run_case_in_memory("stress_impact", Profile::Quick)
        .expect("the stress_impact case's data file must load");
    assert!(
        report.error.is_none(),
        "stress_impact case did not complete: {:?}",
        report.error
    );
    assert!(
        !report.checks.is_empty(),
        "stress_impact produced no checks"
    );
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
        "{} of {} stress_impact checks failed (quick profile, inputs: validation/cases/stress_impact.toml):\n{}",
        failed.len(),
        report.checks.len(),
        failed.join("\n")
    );
}
