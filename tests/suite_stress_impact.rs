//! Gate: the quick profile of the validation case `stress_impact` (a polyhedron at 1200 m/s into a bed and
//! onto a wall: no step error, no tunnelling or pass-through, the time-step guard refusing a step above the
//! stability limit, the tunnelling detector firing when the guard is bypassed) must pass every checked row —
//! the same rows that `cargo validate` writes to `reports/summary.csv`.

use polydem_validation::gate::assert_quick_case;

#[test]
fn stress_impact_case_quick_profile_passes_every_check() {
    assert_quick_case("stress_impact", &[]);
}
