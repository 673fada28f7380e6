//! A run's number of steps is computed with checked arithmetic and held to a stated limit. `end_time = 1e300`,
//! `time_step = 1e-300` or `normal_stiffness = 1e300` (a derived step of 1e-152 s) give step counts beyond
//! the counter (2^64 − 1, where a saturating count would run forever); they are refused at set-up
//! with the field, the count, where Δt came from, and the limit. A run above the default limit of 10^9
//! steps is refused unless `simulation.max_steps` (or `--max-steps` with `--end-time`) raises it.

use std::path::Path;

use polydem::scene::{
    parse_scene, EndTimeError, SceneError, Simulation, StepCountError, DEFAULT_MAX_STEPS,
};

const SCENE: &str = include_str!("../scenes/sphere_bounce.toml");

fn load(text: &str) -> Result<Simulation, SceneError> {
    parse_scene(text, Path::new("bounce.toml"))
}

/// The scene with the line starting with `key =` replaced by `line`.
fn edit(key: &str, line: &str) -> String {
    let prefix = format!("{key} =");
    let mut found = false;
    let text: Vec<String> = SCENE
        .lines()
        .map(|l| {
            if l.starts_with(&prefix) {
                found = true;
                line.to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect();
    assert!(found, "sphere_bounce.toml has a line '{prefix}'");
    text.join("\n")
}

/// The refusal of a scene: its field and message.
fn refusal(text: &str, what: &str) -> (String, String) {
    match load(text) {
        Err(SceneError::Invalid { field, message, .. }) => (field, message),
        Err(other) => panic!("{what}: expected an invalid value, got {other}"),
        Ok(sim) => panic!(
            "{what}: expected a refusal, got a scene of {} steps",
            sim.steps
        ),
    }
}

#[test]
fn step_counts_beyond_the_counter_are_refused_at_set_up_not_saturated() {
    let cases = [
        (
            "end_time = 1e300",
            edit("end_time", "end_time = 1e300"),
            "derived",
        ),
        (
            "time_step = 1e-300",
            edit("steps_per_contact", "time_step = 1e-300"),
            "given by simulation.time_step",
        ),
        (
            "normal_stiffness = 1e300",
            edit("normal_stiffness", "normal_stiffness = 1e300"),
            "derived",
        ),
    ];
    for (what, text, origin) in cases {
        let (field, message) = refusal(&text, what);
        assert_eq!(field, "simulation.end_time", "{what}: {message}");
        for part in ["step counter", origin, "steps"] {
            assert!(
                message.contains(part),
                "{what}: the message names '{part}': {message}"
            );
        }
    }
}

#[test]
fn a_run_above_the_step_limit_is_refused_unless_max_steps_raises_it() {
    // Δt = t_c / 200 = 4.02e-6 s: 1e4 s is 2.49e9 steps, above the default 1e9.
    let long = edit("end_time", "end_time = 1e4");
    let (field, message) = refusal(&long, "end_time = 1e4");
    assert_eq!(field, "simulation.end_time", "{message}");
    let steps = message
        .split(" is ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse::<u64>().ok())
        .unwrap_or_else(|| panic!("the message states the step count: {message}"));
    assert!(
        steps > DEFAULT_MAX_STEPS
            && message.contains(&DEFAULT_MAX_STEPS.to_string())
            && message.contains("simulation.max_steps"),
        "{steps} steps against the limit {DEFAULT_MAX_STEPS}, and how to raise it: {message}"
    );
    let raised = long.replace(
        "end_time = 1e4",
        &format!("end_time = 1e4\nmax_steps = {steps}"),
    );
    let sim = load(&raised).unwrap_or_else(|e| panic!("with max_steps = {steps}: {e}"));
    assert_eq!(
        sim.steps, steps,
        "the run covers the steps the message stated"
    );
    let short = raised.replace(
        &format!("max_steps = {steps}"),
        &format!("max_steps = {}", steps - 1),
    );
    refusal(&short, "max_steps one below the count");
    let zero = raised.replace(&format!("max_steps = {steps}"), "max_steps = 0");
    let (field, message) = refusal(&zero, "max_steps = 0");
    assert_eq!(field, "simulation.max_steps", "{message}");
}

#[test]
fn a_later_end_time_is_held_to_the_same_limits() {
    let mut sim = load(SCENE).unwrap();
    let before = (sim.end_time, sim.steps);
    match sim.set_end_time(1e300) {
        Err(EndTimeError::Steps(StepCountError::Overflow { .. })) => {}
        other => panic!("end time 1e300: expected an overflow refusal, got {other:?}"),
    }
    match sim.set_end_time(1e4) {
        Err(EndTimeError::Steps(StepCountError::AboveLimit { steps, limit, .. })) => {
            assert!(
                steps > limit && limit == DEFAULT_MAX_STEPS,
                "{steps} steps, limit {limit}"
            );
            sim.set_end_time_within(1e4, steps).unwrap();
            assert_eq!(
                sim.steps, steps,
                "raised limit: the run covers the stated steps"
            );
        }
        other => panic!("end time 1e4: expected the limit refusal, got {other:?}"),
    }
    let mut fresh = load(SCENE).unwrap();
    assert!(fresh.set_end_time(1e300).is_err());
    assert_eq!(
        (fresh.end_time, fresh.steps),
        before,
        "a refused end time leaves the run as it was"
    );
}
