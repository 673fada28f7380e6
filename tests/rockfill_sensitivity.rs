//! `polydem rockfill sensitivity` (the paper's claim that stiffness and friction matter little and
//! restitution much, measured from one bed): parameters and values are parsed and checked before any run,
//! each varied run is the run of the file with that one value changed, from the same bed, bit for bit,
//! and the table and CSV hold one row per run.

use polydem_rockfill::experiment::{run_experiment_with, BedSource};
use polydem_rockfill::penetration::PenetrationOptions;
use polydem_rockfill::sensitivity::{
    run_sensitivity, Parameter, SensitivityParams, SensitivityRun, Variation,
};
use polydem_rockfill::study::section_instants;

#[path = "support/rockfill_small.rs"]
mod rockfill_small;
use rockfill_small::small;

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem_{tag}_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

#[test]
fn variations_are_parsed_and_bad_ones_refused_with_the_reason() {
    let v = Variation::parse("friction=0,0.1, 0.4").unwrap();
    assert_eq!(v.parameter, Parameter::Friction);
    assert_eq!(v.values, vec![0.0, 0.1, 0.4]);
    let v = Variation::parse("contact.stiffness_factor=0.25,4").unwrap();
    assert_eq!(v.parameter, Parameter::StiffnessFactor);
    for (text, expected) in [
        ("density=2000", "unknown parameter 'density'"),
        ("contact.friction", "expected KEY=V1,V2"),
        ("friction=0,x", "'x' is not a finite number"),
        ("friction=nan", "'nan' is not a finite number"),
    ] {
        let err = Variation::parse(text).unwrap_err();
        assert!(
            err.contains(expected),
            "'{text}': error '{err}' does not say '{expected}'"
        );
    }
}

#[test]
fn a_variation_changes_only_its_parameter_and_the_laws_check_the_value() {
    let base = small();
    let k4 = Parameter::StiffnessFactor.apply(&base, 4.0).unwrap();
    assert_eq!(
        (k4.contact.normal_stiffness, k4.contact.tangential_stiffness),
        (
            4.0 * base.contact.normal_stiffness,
            4.0 * base.contact.tangential_stiffness
        )
    );
    assert_eq!(
        (
            k4.contact.friction,
            k4.contact.restitution_rocks,
            k4.contact.restitution_projectile
        ),
        (
            base.contact.friction,
            base.contact.restitution_rocks,
            base.contact.restitution_projectile
        )
    );
    let eb = Parameter::RestitutionProjectile.apply(&base, 0.5).unwrap();
    assert_eq!(eb.contact.restitution_projectile, 0.5);
    assert_eq!(eb.contact.restitution_rocks, base.contact.restitution_rocks);
    for (p, value) in [
        (Parameter::Friction, -1.0),
        (Parameter::RestitutionRocks, 1.5),
        (Parameter::StiffnessFactor, 0.0),
        (Parameter::NormalStiffness, -2e7),
    ] {
        let err = p.apply(&base, value).unwrap_err();
        assert!(
            err.contains(p.key()) && err.contains(&format!("{value}")),
            "{} = {value}: error '{err}' names neither the key nor the value",
            p.key()
        );
    }
}

#[test]
fn each_run_is_the_file_with_one_value_changed_from_the_same_bed() {
    let config = small();
    let root = temp_dir("sensitivity");
    let bed = root.join("bed");
    let mut quiet = |_: &str, _: String| {};
    let options = PenetrationOptions {
        snapshot_tip_x: section_instants(&config),
        ..PenetrationOptions::default()
    };
    run_experiment_with(
        &config,
        BedSource::Generate { save: Some(&bed) },
        &options,
        &mut quiet,
    )
    .unwrap();
    let out = root.join("out");
    let params = SensitivityParams {
        base: config,
        bed: bed.clone(),
        variations: vec![
            Variation::parse("friction=0").unwrap(),
            Variation::parse("stiffness_factor=2").unwrap(),
        ],
        out: out.clone(),
        label: "small".into(),
    };
    let runs = run_sensitivity(&params, &mut |_| {}).unwrap();
    let labels: Vec<String> = runs.iter().map(SensitivityRun::label).collect();
    assert_eq!(labels, ["base", "friction_0", "stiffness_factor_2"]);

    // The same runs made directly from the bed with the changed file.
    let mut direct = |c: &polydem_rockfill::config::ExperimentConfig| {
        run_experiment_with(c, BedSource::Load(&bed), &options, &mut quiet)
            .unwrap()
            .penetration
    };
    let mut no_friction = config;
    no_friction.contact.friction = 0.0;
    let mut stiffer = config;
    stiffer.contact.normal_stiffness *= 2.0;
    stiffer.contact.tangential_stiffness *= 2.0;
    for (run, c) in runs.iter().zip([config, no_friction, stiffer]) {
        let p = direct(&c);
        assert_eq!(
            (run.run.residual_speed.to_bits(), run.steps),
            (p.residual_speed.to_bits(), p.steps),
            "{}: residual {} m/s after {} steps, the direct run from the bed {} m/s after {}",
            run.label(),
            run.run.residual_speed,
            run.steps,
            p.residual_speed,
            p.steps
        );
    }
    // Without friction the contacts dissipate (almost) nothing by friction: only the springs stored at
    // packing are released in the first step.
    assert!(
        runs[1].friction < 0.01 * runs[0].friction,
        "friction work with f = 0: {} J, with the file's f: {} J",
        runs[1].friction,
        runs[0].friction
    );

    let csv = std::fs::read_to_string(out.join("sensitivity.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], SensitivityRun::CSV_HEADER);
    assert_eq!(lines.len(), 4, "sensitivity.csv:\n{csv}");
    assert!(lines[2].starts_with("contact.friction,0,"), "{}", lines[2]);
    let table = std::fs::read_to_string(out.join("sensitivity.md")).unwrap();
    for key in [
        "| base |",
        "| contact.friction | 0 |",
        "| contact.stiffness_factor | 2 |",
    ] {
        assert!(
            table.contains(key),
            "sensitivity.md lacks '{key}':\n{table}"
        );
    }
    for label in &labels {
        assert!(
            out.join(label).join("monitors.csv").is_file(),
            "{label}: no monitors.csv"
        );
    }
    std::fs::remove_dir_all(&root).ok();
}

#[test]
fn a_missing_bed_is_refused_before_any_run() {
    let out = temp_dir("sensitivity_nobed");
    let params = SensitivityParams {
        base: small(),
        bed: out.join("no_such_bed"),
        variations: vec![Variation::parse("friction=0").unwrap()],
        out: out.clone(),
        label: "small".into(),
    };
    let err = run_sensitivity(&params, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("no saved bed"), "error: {err}");
    assert!(
        !out.exists(),
        "the output directory was created before the check"
    );
}
