//! Gate: the quick profile of the `sphere_bed` validation case — polydem's run of the sphere-bed
//! penetration (variant b, first 0.6 ms) against the recorded YADE and LIGGGHTS outputs in `reference/`;
//! every checked row must pass. Needs neither YADE nor LIGGGHTS installed. The case documents the setup and
//! the source of every bound (validation/cases/sphere_bed.toml); speed is reported, never asserted here.

use polydem_validation::{run_case_in_memory, Profile};

#[test]
fn sphere_bed_case_passes_every_check() {
    let report =
        run_case_in_memory("sphere_bed", Profile::Quick).expect("sphere_bed case is registered");
    assert!(
        report.error.is_none(),
        "sphere_bed case failed to complete: {:?}",
        report.error
    );
    assert!(
        report.checks.len() >= 5,
        "sphere_bed case produced {} checks, expected at least 5",
        report.checks.len()
    );
    for check in &report.checks {
        assert!(
            check.pass,
            "sphere_bed: {} = {} does not meet the target {} ({})",
            check.metric,
            check.value,
            check.target.render(),
            check.unit
        );
    }
}
