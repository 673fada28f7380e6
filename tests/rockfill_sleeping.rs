//! Sleeping in the rockfill penetration run: the small rockfill bed is packed once, saved,
//! and the penetration is run from it without and with sleeping (`sleeping.penetration`: the bed starts
//! asleep and wakes locally, with the wake limit `wake_contact_fraction` = 0.03 of the rocks' contact forces).
//! - The projectile's residual speed agrees within 0.5 %, and its final velocity
//!   deflection within 0.1°.
//! - Some rock-steps are spent asleep (sleeping did something), and the run from the saved bed with
//!   sleeping is bitwise the run with sleeping straight after packing (the sleeping state is a function of
//!   the saved state).
//!
//! The fractions asleep and the speeds are printed; the quick variant's figures are in the docs
//! (`docs/rockfill.md`, "Sleeping").

use polydem_rockfill::experiment::{run_experiment_with, BedSource};
use polydem_rockfill::penetration::PenetrationOptions;

#[path = "support/rockfill_small.rs"]
mod rockfill_small;
use rockfill_small::small;

#[test]
fn penetration_with_a_sleeping_bed_keeps_the_residual_speed() {
    let dir =
        std::env::temp_dir().join(format!("polydem_rockfill_sleeping_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    let options = PenetrationOptions::default();
    let mut quiet = |_: &str, _: String| {};
    let mut config = small();
    let awake = run_experiment_with(
        &config,
        BedSource::Generate { save: Some(&dir) },
        &options,
        &mut quiet,
    )
    .unwrap();
    config.sleeping.penetration = true;
    config.sleeping.wake_contact_fraction = 0.03;
    let asleep = run_experiment_with(&config, BedSource::Load(&dir), &options, &mut quiet).unwrap();
    let straight = run_experiment_with(
        &config,
        BedSource::Generate { save: None },
        &options,
        &mut quiet,
    )
    .unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let (a, s) = (&awake.penetration, &asleep.penetration);
    let dv = (s.residual_speed - a.residual_speed).abs() / a.residual_speed;
    eprintln!(
        "residual speed without sleeping {} m/s, with {} m/s (relative difference {dv:e}); velocity \
         deflection {}° vs {}°; rock-steps asleep {:.1} %; stage time {:?} vs {:?} ({} rocks, {} steps)",
        a.residual_speed,
        s.residual_speed,
        a.final_velocity_deflection,
        s.final_velocity_deflection,
        100.0 * s.asleep_fraction,
        a.counters.total_time(),
        s.counters.total_time(),
        a.rocks,
        a.steps
    );
    assert!(
        a.residual_speed > 0.5 * config.impact.speed && a.residual_speed < config.impact.speed,
        "residual speed without sleeping {} m/s: the projectile must cross the bed and be slowed (impact {} m/s)",
        a.residual_speed,
        config.impact.speed
    );
    assert!(
        dv <= 5e-3,
        "residual speed with sleeping {} m/s, without {} m/s: relative difference {dv:e}, tolerance 5e-3",
        s.residual_speed,
        a.residual_speed
    );
    let dd = (s.final_velocity_deflection - a.final_velocity_deflection).abs();
    assert!(
        dd <= 0.1,
        "velocity deflection with sleeping {}°, without {}°: difference {dd}°, tolerance 0.1°",
        s.final_velocity_deflection,
        a.final_velocity_deflection
    );
    assert!(
        s.asleep_fraction > 0.0 && a.asleep_fraction == 0.0,
        "rock-steps asleep: {} with sleeping, {} without",
        s.asleep_fraction,
        a.asleep_fraction
    );
    let (rs, rl) = (&straight.penetration.rows, &s.rows);
    assert_eq!(
        rs.len(),
        rl.len(),
        "steps straight after packing vs from the saved bed"
    );
    for (k, (x, y)) in rs.iter().zip(rl).enumerate() {
        assert!(
            x == y,
            "monitor row {k} with sleeping differs: straight after packing {x:?}, from the saved bed {y:?}"
        );
    }
}
