//! The `cargo test` side of a case: run its quick profile in memory and assert its rows, so that the tests
//! and the committed report can never disagree (`tests/suite_*.rs` are one call each).

use crate::case::{Check, Profile};
use crate::runner::run_case_in_memory;

fn describe(check: &Check) -> String {
    format!(
        "{}: measured {:e} {}, target {}",
        check.metric,
        check.value,
        check.unit,
        check.target.render()
    )
}

/// Runs the quick profile of `case` and panics unless it completes with at least one row and every row
/// passes, except the rows named in `not_asserted` — each with the reason it is not asserted (a measured
/// known failure, or a speed figure, which belongs to the report and not to a test on a shared machine).
/// Every named row must still exist; its state is printed with its reason.
pub fn assert_quick_case(case: &str, not_asserted: &[(&str, &str)]) {
    let report = run_case_in_memory(case, Profile::Quick)
        .unwrap_or_else(|e| panic!("case {case} could not start: {e}"));
    assert!(
        report.error.is_none(),
        "case {case} did not complete: {:?}",
        report.error
    );
    assert!(!report.checks.is_empty(), "case {case} produced no checks");
    let exempt = |metric: &str| not_asserted.iter().any(|(m, _)| *m == metric);
    let failed: Vec<String> = report
        .checks
        .iter()
        .filter(|c| !c.pass && !exempt(&c.metric))
        .map(describe)
        .collect();
    assert!(
        failed.is_empty(),
        "{} of {} {case} checks failed (quick profile, inputs: validation/cases/{case}.toml):\n{}",
        failed.len(),
        report.checks.len(),
        failed.join("\n")
    );
    for (metric, reason) in not_asserted {
        let row = report
            .checks
            .iter()
            .find(|c| c.metric == *metric)
            .unwrap_or_else(|| {
                panic!("{case}: row {metric} is listed as not asserted but no longer exists")
            });
        assert!(
            row.value.is_finite(),
            "{case}: row {metric} is not a finite number: {}",
            describe(row)
        );
        let state = if row.pass { "passes" } else { "fails" };
        eprintln!(
            "{case}: not asserted ({state}): {} — {reason}",
            describe(row)
        );
    }
}
