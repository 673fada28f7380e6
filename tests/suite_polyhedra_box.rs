//! Gate: the quick profile of the `polyhedra_box` validation case (issue 4) completes, its polydem run
//! has no non-finite state and its energy ledger closes within the case's bound. The speed row (YADE's
//! CPU time per step over polydem's, target 200×) is a figure of the report, not of this gate: speed
//! targets live in benchmarks and reports, never in tests on a shared machine.

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn polyhedra_box_case_runs_and_its_physics_rows_pass() {
    let report = run_case_in_memory("polyhedra_box", Profile::Quick)
        .expect("polyhedra_box case is registered");
    assert!(
        report.error.is_none(),
        "polyhedra_box case failed to complete: {:?}",
        report.error
    );
    let speed = report
        .checks
        .iter()
        .find(|c| c.metric == "yade_over_polydem_cpu_time")
        .expect("the speed row is reported");
    assert!(
        speed.value.is_finite() && speed.value > 0.0,
        "speed ratio {} is not a positive number",
        speed.value
    );
    let physics: Vec<_> = report
        .checks
        .iter()
        .filter(|c| c.metric != "yade_over_polydem_cpu_time")
        .collect();
    assert!(
        physics.len() >= 2,
        "expected the energy and finiteness rows, got {physics:?}"
    );
    for check in physics {
        assert!(
            check.pass,
            "polyhedra_box: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
