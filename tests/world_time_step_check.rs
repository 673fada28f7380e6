//! The check of the time step during the run (`polydem::world::step` module `guard`).
//!
//! The time step is checked at load against the stability limit at the scene's declared
//! `characteristic_speed`. A scene that declares 5 m/s and then collides two Hertz-law steel spheres at
//! ±1200 m/s with Δt = 0.99 of that limit ran to its end and lost most of the energy of an elastic
//! impact, exit 0; a body at 1e6 m/s passed through another with no pair ever tested. These tests
//! hold the run-time check to both, on the general step and on the flat sphere layout, and hold it to
//! reading the state only (a run with the check warning is the same bits as a run without it).

use std::path::Path;

use polydem::math::{Real, Vector};
use polydem::scene::{parse_scene, SceneError, Simulation};
use polydem::world::{
    step, ContactKey, SphereSim, StepError, StepScratch, TimeStepCheck, TimeStepFinding,
};

const RADIUS: Real = 0.01;

/// Two steel spheres of radius 1 cm (47 kJ of kinetic energy at ±1200 m/s), Hertz–Mindlin, elastic,
/// frictionless, no gravity, `gap` (m) apart; `speed` (m/s) each, towards each other; the step given
/// by `step_line`.
fn impact_scene(speed: Real, gap: Real, step_line: &str, check: Option<&str>) -> String {
    let x = RADIUS + 0.5 * gap;
    let check = check
        .map(|c| format!("time_step_check = \"{c}\"\n"))
        .unwrap_or_default();
    format!(
        r#"[simulation]
gravity = [0.0, 0.0, 0.0]
end_time = 2.0e-4
output_interval = 1.0e-5
characteristic_speed = 5.0
{step_line}
{check}
[[material]]
name = "steel"
density = 7800.0
young_modulus = 2.0e11
poisson_ratio = 0.3

[[interaction]]
materials = ["steel", "steel"]
law = "hertz_mindlin"
restitution = 1.0
friction = 0.0

[[shape]]
name = "ball"
kind = "sphere"
radius = {RADIUS}

[[body]]
name = "left"
shape = "ball"
material = "steel"
position = [{left}, 0.0, 0.0]
velocity = [{speed}, 0.0, 0.0]

[[body]]
name = "right"
shape = "ball"
material = "steel"
position = [{x}, 0.0, 0.0]
velocity = [{neg}, 0.0, 0.0]
"#,
        left = -x,
        neg = -speed,
    )
}

fn parse(text: &str) -> Result<Simulation, SceneError> {
    parse_scene(text, Path::new("time_step_check.toml"))
}

/// The impact scene with Δt = 0.99 of the stability limit the load-time guard reports at 5 m/s, the
/// gap `gap` (m) after `flight` steps of free flight.
fn impact_at_099_of_the_limit(
    speed: Real,
    gap: Real,
    flight: Real,
    check: Option<&str>,
) -> Simulation {
    let probe = parse(&impact_scene(speed, gap, "steps_per_contact = 100", None)).unwrap();
    let dt = 0.99 * probe.time_step.stability_limit;
    let start = gap + flight * 2.0 * speed * dt;
    parse(&impact_scene(
        speed,
        start,
        &format!("time_step = {dt:e}"),
        check,
    ))
    .unwrap()
}

fn kinetic(sim: &Simulation) -> Real {
    sim.world
        .bodies()
        .iter()
        .map(|b| 0.5 * b.mass * b.velocity.norm_squared())
        .sum()
}

/// Runs the general step until it fails or `steps` are done; the error, if any, and the reports.
fn run_general(
    sim: &mut Simulation,
    steps: u64,
) -> (Option<StepError>, Vec<polydem::world::StepReport>) {
    let mut scratch = StepScratch::default();
    let mut reports = Vec::new();
    for _ in 0..steps {
        match step(&sim.params, &mut sim.world, &mut scratch) {
            Ok(r) => reports.push(r),
            Err(e) => return (Some(e), reports),
        }
    }
    (None, reports)
}

/// The same on the flat sphere layout.
fn run_flat(sim: &Simulation, steps: u64) -> (Option<StepError>, Vec<polydem::world::StepReport>) {
    let mut flat = SphereSim::from_world(&sim.world, &sim.params).expect("a sphere-only world");
    let mut reports = Vec::new();
    let result = flat.run_steps(steps, |_, r| {
        reports.push(r.clone());
        std::ops::ControlFlow::Continue(())
    });
    (result.err(), reports)
}

/// `speed`: the approach speed the finding must name (free flight up to the check), or none when the
/// pair met and rebounded between two checks (then only above the critical speed).
fn assert_fast_approach(error: Option<StepError>, path: &str, speed: Option<Real>) {
    let Some(StepError::TimeStep { step, finding }) = error else {
        panic!("{path}: expected the time-step check to stop the run, got {error:?}");
    };
    let message = StepError::TimeStep {
        step,
        finding: finding.clone(),
    }
    .to_string();
    let TimeStepFinding::FastApproach {
        key,
        speed: found,
        critical_speed,
        limit,
        dt,
        ..
    } = *finding
    else {
        panic!("{path}: expected a fast approach, got {finding:?}");
    };
    assert_eq!(key, ContactKey::Body { a: 0, b: 1 }, "{path}: {message}");
    // Free flight before the contact: the approach speed is the sum of the two speeds.
    if let Some(speed) = speed {
        let rel = (found - 2.0 * speed).abs() / (2.0 * speed);
        assert!(
            rel < 1e-12,
            "{path}: approach speed {found} m/s, expected {} m/s (relative error {rel:e} > 1e-12)",
            2.0 * speed
        );
        assert_eq!(step, 1, "{path}: {message}");
    }
    assert!(
        critical_speed < found && limit < dt,
        "{path}: critical speed {critical_speed} m/s and limit {limit} s at {found} m/s against the step {dt} s: {message}"
    );
    for part in ["'left'", "'right'", "m/s", "time_step_check"] {
        assert!(
            message.contains(part),
            "{path}: the message lacks {part:?}: {message}"
        );
    }
}

/// ±1200 m/s Hertz impact declared at 5 m/s, Δt = 0.99 of the reported limit: the default check stops
/// the run before the contact is stepped through (the pair listed 1 mm apart after the first step),
/// naming the pair, its speed and the limit, on both step paths.
#[test]
fn hertz_impact_faster_than_the_characteristic_speed_stops_the_run_on_both_paths() {
    let speed = 1200.0;
    let sim = impact_at_099_of_the_limit(speed, 1e-3, 1.0, None);
    assert_eq!(sim.params.time_step_check, TimeStepCheck::Stop);
    let (error, _) = run_general(&mut sim.clone(), 10_000);
    assert_fast_approach(error, "general step", Some(speed));
    let (error, _) = run_flat(&sim, 10_000);
    assert_fast_approach(error, "flat layout", Some(speed));
}

/// The same impact when the spheres go from 1 mm apart to a deep overlap within one step (never seen
/// apart and listed): the check meets them within reach, rebounding faster than the critical speed,
/// and stops the run there, on both paths.
#[test]
fn hertz_impact_met_between_two_checks_stops_at_its_rebound() {
    let sim = impact_at_099_of_the_limit(1200.0, 1e-3, 0.0, None);
    let (error, _) = run_general(&mut sim.clone(), 10_000);
    assert_fast_approach(error, "general step", None);
    let (error, _) = run_flat(&sim, 10_000);
    assert_fast_approach(error, "flat layout", None);
}

/// The same impact with the check off runs to its end and loses most of the energy of an elastic
/// impact (the silent wrong answer the check prevents); with the check warning it is the same run, bit
/// for bit, and every step that met the pair too fast says so.
#[test]
fn warn_reports_the_fast_impact_and_moves_no_bit_of_the_run() {
    let speed = 1200.0;
    let steps = 400;
    let mut off = impact_at_099_of_the_limit(speed, 1e-3, 1.0, Some("off"));
    let mut warn = impact_at_099_of_the_limit(speed, 1e-3, 1.0, Some("warn"));
    let before = kinetic(&off);
    let (error_off, reports_off) = run_general(&mut off, steps);
    let (error_warn, reports_warn) = run_general(&mut warn, steps);
    assert!(
        error_off.is_none() && error_warn.is_none(),
        "off: {error_off:?}, warn: {error_warn:?}"
    );
    for (i, (a, b)) in off
        .world
        .bodies()
        .iter()
        .zip(warn.world.bodies())
        .enumerate()
    {
        assert!(
            a.position == b.position && a.velocity == b.velocity,
            "body {i}: off {:?} {:?}, warn {:?} {:?}",
            a.position,
            a.velocity,
            b.position,
            b.velocity
        );
    }
    let change = (kinetic(&off) / before - 1.0).abs();
    assert!(
        change > 0.1,
        "the unchecked elastic impact ends with {} of {before} J (changed by {change} of it); the hazard this check exists for is gone?",
        kinetic(&off)
    );
    assert!(reports_off.iter().all(|r| r.time_step_findings.is_empty()));
    let warned = reports_warn
        .iter()
        .filter(|r| {
            r.time_step_findings
                .iter()
                .any(|f| matches!(f, TimeStepFinding::FastApproach { .. }))
        })
        .count();
    assert!(
        warned > 0,
        "no step warned of the {speed} m/s impact (energy changed by {change} of it)"
    );
}

/// A scene that declares its real impact speed runs its impact at 0.99 of the limit with no finding on
/// either path: the check does not second-guess an honest declaration.
#[test]
fn impact_at_the_declared_speed_runs_without_a_finding() {
    let speed = 2.5;
    let sim = impact_at_099_of_the_limit(speed, 1e-4, 0.0, None);
    let steps = 400;
    let (error, reports) = run_general(&mut sim.clone(), steps);
    assert!(error.is_none(), "general step: {error:?}");
    assert!(
        reports.iter().any(|r| r.contacts > 0),
        "the spheres never met in {steps} steps"
    );
    let (error, reports) = run_flat(&sim, steps);
    assert!(error.is_none(), "flat layout: {error:?}");
    assert!(reports.iter().any(|r| r.contacts > 0));
}

/// A body at 1e6 m/s towards another: without the check it passes through with no contact ever
/// evaluated; with it the run stops at the first step, naming the body, its speed and its move.
#[test]
fn body_at_a_million_metres_per_second_stops_instead_of_passing_through() {
    let speed = 1e6;
    let unchecked = |check: &str| {
        let mut sim = impact_at_099_of_the_limit(speed, 0.05, 0.0, Some(check));
        sim.world
            .set_body_velocity(1, Vector::zeros())
            .expect("a body");
        sim
    };
    // Off: the body ends beyond the other, no contact.
    let mut off = unchecked("off");
    let (error, reports) = run_general(&mut off, 3);
    assert!(error.is_none(), "{error:?}");
    let contacts: usize = reports.iter().map(|r| r.contacts).sum();
    let (x0, x1) = (
        off.world.bodies()[0].position.x,
        off.world.bodies()[1].position.x,
    );
    assert!(
        x0 > x1 + 2.0 * RADIUS && contacts == 0,
        "the fast body at x = {x0} m, the other at {x1} m, contacts {contacts}: expected it through with none"
    );
    let stop = unchecked("stop");
    for (path, error) in [
        ("general step", run_general(&mut stop.clone(), 3).0),
        ("flat layout", run_flat(&stop, 3).0),
    ] {
        let Some(StepError::TimeStep { step, finding }) = error else {
            panic!("{path}: expected the check to stop the run, got {error:?}");
        };
        let TimeStepFinding::Tunnelling {
            body,
            speed: found,
            displacement,
            closing,
            smallest_radius,
            ..
        } = *finding
        else {
            panic!("{path}: expected a tunnelling finding, got {finding:?}");
        };
        assert_eq!((step, body), (1, 0), "{path}: {finding:?}");
        // The other body is still: the closing bound is the fast body's own move.
        assert!(
            (found - speed).abs() <= 1e-12 * speed
                && closing == displacement
                && displacement > smallest_radius
                && smallest_radius == RADIUS,
            "{path}: speed {found} m/s (expected {speed}), move {displacement} m, closing bound {closing} m, smallest radius {smallest_radius} m (expected {RADIUS})"
        );
    }
}

/// Bodies that move more than half the skin in one step are counted (as "dangerous builds"), one per
/// body and step, and are not a finding while the two close by less than the smallest radius per step.
#[test]
fn moves_beyond_half_the_skin_are_counted_per_body_and_step() {
    let mut sim = impact_at_099_of_the_limit(1.0, 0.05, 0.0, None);
    let skin = sim.world.broad_phase().skin();
    let dt = sim.params.dt;
    // 0.75 of the skin per step: beyond half of it, far below the diameter.
    let speed = 0.75 * skin / dt;
    assert!(2.0 * speed * dt < RADIUS, "skin {skin} m, step {dt} s");
    sim.world
        .set_body_velocity(0, Vector::new(-speed, 0.0, 0.0))
        .expect("a body");
    sim.world
        .set_body_velocity(1, Vector::new(speed, 0.0, 0.0))
        .expect("a body");
    let steps = 5;
    let (error, reports) = run_general(&mut sim.clone(), steps);
    assert!(error.is_none(), "{error:?}");
    let counted: u64 = reports.iter().map(|r| r.counters.dangerous_moves).sum();
    assert_eq!(counted, 2 * steps, "general step, speed {speed} m/s");
    let (error, reports) = run_flat(&sim, steps);
    assert!(error.is_none(), "{error:?}");
    let counted: u64 = reports.iter().map(|r| r.counters.dangerous_moves).sum();
    assert_eq!(counted, 2 * steps, "flat layout, speed {speed} m/s");
}

/// `time_step_check` takes "stop", "warn" or "off"; anything else is refused with the file, the line
/// and the field.
#[test]
fn time_step_check_key_is_read_and_checked_like_every_scene_key() {
    for (value, want) in [
        ("stop", TimeStepCheck::Stop),
        ("warn", TimeStepCheck::Warn),
        ("off", TimeStepCheck::Off),
    ] {
        let sim = parse(&impact_scene(1.0, 1e-3, "time_step = 1e-7", Some(value))).unwrap();
        assert_eq!(sim.params.time_step_check, want, "value {value:?}");
    }
    let text = impact_scene(1.0, 1e-3, "time_step = 1e-7", Some("sometimes"));
    let line = text
        .lines()
        .position(|l| l.starts_with("time_step_check"))
        .unwrap()
        + 1;
    match parse(&text) {
        Err(e @ SceneError::Invalid { .. }) => {
            let message = e.to_string();
            let want = format!("time_step_check.toml:{line}: simulation.time_step_check:");
            assert!(
                message.starts_with(&want) && message.contains("\"sometimes\""),
                "message {message:?}, expected it to start with {want:?} and name the value"
            );
        }
        other => panic!("expected an invalid-field error, got {other:?}"),
    }
}

/// Two bodies each moving 0.6 of the smallest radius per step towards each other close by 1.2 of it:
/// a finding at the first step, though neither alone moves a radius; at 0.4 each (closing 0.8) the
/// run goes on (the pair is still far from listed, so no approach speed is judged either).
#[test]
fn two_bodies_closing_by_more_than_the_smallest_radius_per_step_stop() {
    for (fraction, stops) in [(0.6, true), (0.4, false)] {
        let mut sim = impact_at_099_of_the_limit(1.0, 1.0, 0.0, None);
        let speed = fraction * RADIUS / sim.params.dt;
        sim.world
            .set_body_velocity(0, Vector::new(speed, 0.0, 0.0))
            .expect("a body");
        sim.world
            .set_body_velocity(1, Vector::new(-speed, 0.0, 0.0))
            .expect("a body");
        for (path, error) in [
            ("general step", run_general(&mut sim.clone(), 3).0),
            ("flat layout", run_flat(&sim, 3).0),
        ] {
            match (&error, stops) {
                (Some(StepError::TimeStep { step: 1, finding }), true) => {
                    let TimeStepFinding::Tunnelling { closing, .. } = **finding else {
                        panic!("{path}: expected a tunnelling finding, got {finding:?}");
                    };
                    let want = 2.0 * fraction * RADIUS;
                    assert!(
                        (closing - want).abs() <= 1e-12 * want,
                        "{path}: closing bound {closing} m, expected {want} m"
                    );
                }
                (None, false) => {}
                _ => panic!(
                    "{path}: each body {fraction} of the radius per step: expected {}, got {error:?}",
                    if stops { "a stop at step 1" } else { "no finding" }
                ),
            }
        }
    }
}
