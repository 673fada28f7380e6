//! `polydem rockfill` refuses, before the work starts, a run beyond its stated limits, and a bed of another
//! rock size:
//! - `--size 12` on the quick layer means 5 million rocks (memory without bound, no output for minutes):
//!   refused before any seed is drawn, with the rock count, the memory estimate and `--max-rocks`;
//! - `travel_per_step = 1e-12` gives Δt = 2.4e-16 s and a run that never ends: refused before generation
//!   with its step count and `--max-steps`, and again when the Δt of a loaded bed is known;
//! - a bed recorded at 290 mm run with `--size 200` was labelled 200 mm and stepped with 200 mm's Δt:
//!   refused with both sizes.

use polydem_rockfill::experiment::{run_experiment_with, BedSource, ExperimentError};
use polydem_rockfill::limits::{LimitError, DEFAULT_MAX_ROCKS};
use polydem_rockfill::packing::PackingError;
use polydem_rockfill::penetration::{PenetrationError, PenetrationOptions};

#[path = "support/rockfill_small.rs"]
mod rockfill_small;
use rockfill_small::small;

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem_{tag}_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

#[test]
fn a_sample_above_the_rock_limit_is_refused_before_generation() {
    let mut config = polydem_rockfill::config::ExperimentConfig::quick();
    config.rock.mean_size = 0.012;
    let start = std::time::Instant::now();
    let mut quiet = |_: &str, _: String| {};
    let got = run_experiment_with(
        &config,
        BedSource::Generate { save: None },
        &PenetrationOptions::default(),
        &mut quiet,
    );
    let elapsed = start.elapsed().as_secs_f64();
    match got {
        Err(ExperimentError::Limit(e @ LimitError::TooManyRocks { rocks, limit, .. })) => {
            let message = e.to_string();
            assert!(
                rocks > 1e6 && limit == DEFAULT_MAX_ROCKS,
                "{rocks} rocks against the limit {limit}: {message}"
            );
            for part in ["12 mm", "GB", "--max-rocks", "limits.max_rocks"] {
                assert!(
                    message.contains(part),
                    "the message names '{part}': {message}"
                );
            }
        }
        Err(other) => panic!("12 mm rocks: expected TooManyRocks, got {other}"),
        Ok(_) => panic!("12 mm rocks: expected a refusal, the run went through"),
    }
    // Refused before generation: no tessellation of millions of seeds happened.
    assert!(elapsed < 5.0, "the refusal took {elapsed:.2} s");
}

#[test]
fn a_penetration_step_too_small_is_refused_with_its_step_count() {
    let mut config = small();
    config.impact.travel_per_step = 1e-12;
    let mut quiet = |_: &str, _: String| {};
    let options = PenetrationOptions::default();
    match run_experiment_with(
        &config,
        BedSource::Generate { save: None },
        &options,
        &mut quiet,
    ) {
        Err(ExperimentError::Limit(
            e @ LimitError::TooManySteps {
                stage,
                steps,
                limit,
                ..
            },
        )) => {
            let message = e.to_string();
            assert!(
                stage == "penetration" && steps > limit as f64,
                "{stage}: {steps:e} steps, limit {limit}: {message}"
            );
            for part in ["impact.travel_per_step", "--max-steps", "GB"] {
                assert!(
                    message.contains(part),
                    "the message names '{part}': {message}"
                );
            }
        }
        Err(other) => panic!("travel_per_step = 1e-12: expected TooManySteps, got {other}"),
        Ok(_) => panic!("travel_per_step = 1e-12: expected a refusal"),
    }
}

/// Packing and the penetration of a loaded bed check their own step counts once Δt is known: a limit
/// below the small experiment's packing is refused at packing, and one below its penetration at the
/// penetration of the saved bed; raising it runs the same experiment.
#[test]
fn packing_and_penetration_check_their_steps_once_the_time_step_is_known() {
    let dir = temp_dir("limits_bed");
    let mut quiet = |_: &str, _: String| {};
    let options = PenetrationOptions::default();
    let mut tight = small();
    tight.limits.max_steps = 1000;
    // A short impact, so that its bound known before generation (~2 steps) passes and the packing's is hit.
    tight.impact.max_time = 1e-5;
    match run_experiment_with(
        &tight,
        BedSource::Generate { save: None },
        &options,
        &mut quiet,
    ) {
        Err(ExperimentError::Packing(PackingError::Limit(LimitError::TooManySteps {
            stage: "packing",
            ..
        }))) => {}
        Err(other) => panic!("max_steps 1000: expected the packing's refusal, got {other}"),
        Ok(_) => panic!("max_steps 1000: expected the packing's refusal"),
    }
    let config = small();
    let run = run_experiment_with(
        &config,
        BedSource::Generate { save: Some(&dir) },
        &options,
        &mut quiet,
    )
    .unwrap();
    let steps = run.penetration.steps;
    let mut short = small();
    // Below the penetration's bound max_time / Δt but above what the travel bound alone allows.
    let bound = (config.impact.max_time / run.penetration.dt).ceil() as u64;
    short.limits.max_steps = bound - 1;
    let got = run_experiment_with(&short, BedSource::Load(&dir), &options, &mut quiet);
    std::fs::remove_dir_all(&dir).ok();
    match got {
        Err(ExperimentError::Penetration(PenetrationError::Limit(LimitError::TooManySteps {
            stage: "penetration",
            limit,
            ..
        }))) => assert_eq!(limit, bound - 1),
        Err(other) => panic!("max_steps {}: expected the penetration's refusal, got {other}", bound - 1),
        Ok(_) => panic!(
            "max_steps {} (run of {steps} steps, bound {bound}): expected the penetration's refusal",
            bound - 1
        ),
    }
}

#[test]
fn a_bed_of_another_rock_size_is_refused_naming_both_sizes() {
    let dir = temp_dir("limits_bed_size");
    let mut quiet = |_: &str, _: String| {};
    let options = PenetrationOptions {
        max_steps: Some(5),
        ..PenetrationOptions::default()
    };
    let config = small();
    run_experiment_with(
        &config,
        BedSource::Generate { save: Some(&dir) },
        &options,
        &mut quiet,
    )
    .unwrap();
    let mut other = small();
    other.rock.mean_size = 0.2;
    let got = run_experiment_with(&other, BedSource::Load(&dir), &options, &mut quiet);
    let same = run_experiment_with(&config, BedSource::Load(&dir), &options, &mut quiet);
    std::fs::remove_dir_all(&dir).ok();
    match got {
        Err(e @ ExperimentError::BedSize { .. }) => {
            let message = e.to_string();
            for part in ["290 mm", "200 mm", "--size 290"] {
                assert!(
                    message.contains(part),
                    "the message names '{part}': {message}"
                );
            }
        }
        Err(other) => panic!("200 mm run on a 290 mm bed: expected BedSize, got {other}"),
        Ok(_) => panic!("200 mm run on a 290 mm bed: expected a refusal"),
    }
    assert!(same.is_ok(), "the bed's own size runs: {:?}", same.err());
}
