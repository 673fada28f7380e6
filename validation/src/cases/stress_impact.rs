//! Stability stress test, extreme impacts: a steel polyhedron at 1200 m/s into a small bed of
//! rock polyhedra in a closed box, and into a wall. Checked: no step error (non-finite state, failed
//! query), no tunnelling and no pass-through ([`polydem::world::tunnelling`] defines both), the time-step
//! guard of the scene refusing a step above the stability limit and admitting one just below it (and the
//! run at that step not tunnelling either), and the detector's own sensitivity: with the guard bypassed
//! and a step so coarse that the projectile moves a particle size per step, it must report tunnelling.

use polydem::math::{Real, Vector};
use polydem::scene::{SceneError, Simulation, TimeStepInfo};
use polydem::world::TimeStepCheck;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

use super::stress_util::{
    box_points, ellipsoid_points, random_unit, run_monitored, MonitoredRun, SceneText,
};
use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

pub struct StressImpact;

const CASE: &str = "stress_impact";

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    speed: Real,
    /// Bed lattice (sites per axis) and spacing (m); particle radius = 0.45 × spacing.
    bed: [usize; 3],
    spacing: Real,
    /// Projectile half extents (m).
    projectile_half_extents: [Real; 3],
    rock_density: Real,
    steel_density: Real,
    normal_stiffness: Real,
    restitution: Real,
    steps_per_contact: Real,
    /// Simulated time (s) of the bed and wall impacts.
    duration: Real,
    /// The refused step, as a multiple of the stability limit.
    refused_factor: Real,
    /// The admitted step, as a multiple of the stability limit.
    admitted_factor: Real,
    /// Steps of the guard-bypassed runs and their Δt (s).
    bypass_steps: u64,
    bypass_dt: Real,
    seed: u64,
}

/// The bed scene (`wall_only` = no bed: the projectile hits the floor).
fn scene(p: &Params, time_step: (&str, Real), wall_only: bool) -> SceneText {
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let s = p.spacing;
    let r = 0.45 * s;
    let extent = Vector::new(p.bed[0] as Real * s, p.bed[1] as Real * s, 0.0);
    let bed_top = p.bed[2] as Real * s;
    let h = Vector::from(p.projectile_half_extents);
    let start_gap = 0.5 * s;
    let top = bed_top + start_gap + 3.0 * h.norm();
    let mut t = SceneText::new(
        Vector::new(0.0, 0.0, -9.81),
        p.duration,
        p.duration / 200.0,
        time_step,
    );
    t.material("rock", p.rock_density)
        .material("steel", p.steel_density)
        .interaction("rock", "rock", p.normal_stiffness, None, p.restitution)
        .interaction("rock", "steel", p.normal_stiffness, None, p.restitution)
        .interaction("steel", "steel", p.normal_stiffness, None, p.restitution);
    t.polyhedron("projectile", &box_points(&h));
    let n_shapes = 3;
    for k in 0..n_shapes {
        let axes = Vector::new(
            r,
            r * rng.random_range(0.6..1.0),
            r * rng.random_range(0.5..1.0),
        );
        t.polyhedron(&format!("rock{k}"), &ellipsoid_points(&mut rng, 14, &axes));
    }
    let centre_xy = Vector::new(extent.x / 2.0, extent.y / 2.0, 0.0);
    if !wall_only {
        let mut k = 0;
        for i in 0..p.bed[0] {
            for j in 0..p.bed[1] {
                for l in 0..p.bed[2] {
                    let pos = Vector::new(i as Real + 0.5, j as Real + 0.5, l as Real + 0.5) * s;
                    let aa = random_unit(&mut rng) * rng.random_range(0.0..3.0);
                    t.body(
                        &format!("rock{k}"),
                        &format!("rock{}", k % n_shapes),
                        "rock",
                        &pos,
                        &aa,
                        &Vector::zeros(),
                        &Vector::zeros(),
                    );
                    k += 1;
                }
            }
        }
    }
    // The projectile: tilted (vertex and edge first), slightly off the bed's centre line, spinning.
    let start_z = if wall_only {
        0.5 * s + h.norm()
    } else {
        bed_top + start_gap
    };
    let offset = Vector::new(0.13 * s, -0.07 * s, start_z);
    let v = Vector::new(0.02, -0.01, -1.0).normalize() * p.speed;
    t.body(
        "projectile",
        "projectile",
        "steel",
        &(centre_xy + offset),
        &Vector::new(0.3, 0.5, 0.2),
        &v,
        &Vector::new(50.0, -30.0, 80.0),
    );
    let hi = Vector::new(extent.x, extent.y, top);
    t.closed_box("steel", &Vector::zeros(), &hi);
    t
}

fn projectile(sim: &Simulation) -> usize {
    sim.world
        .names()
        .iter()
        .position(|n| n == "projectile")
        .unwrap_or(0)
}

/// One run: the monitored counts, the projectile's speed and height, and the energy balance over time.
struct ImpactRun {
    run: MonitoredRun,
    dt: Real,
    speed: Vec<(Real, Real)>,
    height: Vec<(Real, Real)>,
    final_velocity: Vector,
    /// Largest upward velocity of the projectile's centre (m/s) among the samples.
    max_vz: Real,
}

fn impact_run(mut sim: Simulation, steps: u64, samples: u64) -> ImpactRun {
    let i = projectile(&sim);
    let (mut speed, mut height) = (Vec::new(), Vec::new());
    let mut max_vz = Real::NEG_INFINITY;
    let run = run_monitored(&mut sim, steps, (steps / samples).max(1), |s| {
        let b = &s.world.bodies()[i];
        speed.push((s.world.time() * 1e3, b.velocity.norm()));
        height.push((s.world.time() * 1e3, b.position.z));
        max_vz = max_vz.max(b.velocity.z);
    });
    ImpactRun {
        run,
        dt: sim.params.dt,
        speed,
        height,
        final_velocity: sim.world.bodies()[i].velocity,
        max_vz,
    }
}

/// The line of the scene text on which `key = ` first appears (1-based).
fn line_of(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| l.trim_start().starts_with(&format!("{key} =")))
        .map_or(0, |i| i + 1)
}

impl Case for StressImpact {
    fn name(&self) -> &'static str {
        CASE
    }
    fn data(&self) -> &'static str {
        include_str!("../../cases/stress_impact.toml")
    }
    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(CASE, profile)?;
        let tol = Tolerances {
            energy: data.tolerance(CASE, "energy_error_max")?.value,
            overlap: data.tolerance(CASE, "overlap_max")?.value,
        };
        ctx.progress().stage("impacts", 6);
        let runs = impacts(ctx, &p)?;
        check_impacts(ctx, &runs, &tol);
        report_guard(ctx, &p, &runs);
        report_runs(ctx, &runs)?;
        plot_impacts(ctx, &p, &runs)
    }
}

struct Tolerances {
    energy: Real,
    overlap: Real,
}

/// What the guard said of a step above the limit, and the step just below it that it admitted.
struct GuardProbe {
    /// Refused as an invalid `simulation.time_step`.
    refused: bool,
    /// The refusal named the line of `time_step`.
    named_line: bool,
    refusal: String,
    admitted_dt: Real,
}

/// Every run of the case.
struct Impacts {
    info: TimeStepInfo,
    bed: ImpactRun,
    wall: ImpactRun,
    limit: ImpactRun,
    bypass_bed: ImpactRun,
    bypass_wall: ImpactRun,
    guard: GuardProbe,
}

/// The impacts at the derived step (t_c/N) in the bed and on the wall, the guard's probe and the run
/// just below the limit, and the runs with the guard bypassed.
fn impacts(ctx: &mut CaseContext, p: &Params) -> Result<Impacts, SuiteError> {
    let derived = ("steps_per_contact", p.steps_per_contact);
    let bed = scene(p, derived, false).build(CASE, "bed")?;
    let info = bed.time_step;
    let steps_for = |dt: Real| (p.duration / dt).ceil() as u64;
    let bed_run = impact_run(bed, steps_for(info.dt), 400);
    ctx.progress().inc(1);
    let wall = scene(p, derived, true).build(CASE, "wall")?;
    let wall_dt = wall.params.dt;
    let wall_run = impact_run(wall, steps_for(wall_dt), 400);
    ctx.progress().inc(1);

    // The guard: a step above the limit is refused, naming the line of `time_step`; one just below is
    // admitted, and the bed run with it must not tunnel either.
    let refused_text = scene(
        p,
        ("time_step", p.refused_factor * info.stability_limit),
        false,
    );
    let expected_line = line_of(refused_text.text(), "time_step");
    let (refused, named_line, refusal) = match refused_text.try_build("bed_refused") {
        Err(SceneError::Invalid {
            line,
            field,
            message,
            ..
        }) => (
            field == "simulation.time_step",
            line == expected_line,
            format!("line {line}: {field}: {message}"),
        ),
        Err(e) => (false, false, e.to_string()),
        Ok(sim) => (false, false, format!("admitted Δt = {:e} s", sim.params.dt)),
    };
    ctx.progress().inc(1);
    let admitted = scene(
        p,
        ("time_step", p.admitted_factor * info.stability_limit),
        false,
    )
    .build(CASE, "bed_admitted")?;
    let admitted_dt = admitted.params.dt;
    let limit_run = impact_run(admitted, steps_for(admitted_dt), 400);
    ctx.progress().inc(1);

    // The detector's sensitivity: the guard bypassed (Δt set after building, the step's own check of
    // Δt off: it would stop the run before the detector sees the crossing), a step in which the
    // projectile moves about a particle size.
    let mut bypass_bed = scene(p, derived, false).build(CASE, "bed_bypass")?;
    bypass_bed.params.dt = p.bypass_dt;
    bypass_bed.params.time_step_check = TimeStepCheck::Off;
    let bypass_bed_run = impact_run(bypass_bed, p.bypass_steps, p.bypass_steps);
    ctx.progress().inc(1);
    let mut bypass_wall = scene(p, derived, true).build(CASE, "wall_bypass")?;
    bypass_wall.params.dt = p.bypass_dt;
    bypass_wall.params.time_step_check = TimeStepCheck::Off;
    let bypass_wall_run = impact_run(bypass_wall, p.bypass_steps, p.bypass_steps);
    ctx.progress().inc(1);

    Ok(Impacts {
        info,
        bed: bed_run,
        wall: wall_run,
        limit: limit_run,
        bypass_bed: bypass_bed_run,
        bypass_wall: bypass_wall_run,
        guard: GuardProbe {
            refused,
            named_line,
            refusal,
            admitted_dt,
        },
    })
}

/// The gated rows: no step error, tunnelling or pass-through at or below the limit, the energy and
/// overlap of the derived step, the guard's refusal, and the detector catching the bypassed runs.
fn check_impacts(ctx: &mut CaseContext, r: &Impacts, tol: &Tolerances) {
    for (name, run) in [
        ("bed", &r.bed),
        ("wall", &r.wall),
        ("bed_at_limit", &r.limit),
    ] {
        let run = &run.run;
        ctx.check(
            &format!("{name}_step_errors"),
            if run.step_error.is_some() { 1.0 } else { 0.0 },
            Target::equal(0.0),
            "1",
        );
        ctx.check(
            &format!("{name}_tunnelling_missed_contact"),
            run.crossings.missed() as f64,
            Target::equal(0.0),
            "1",
        );
        ctx.check(
            &format!("{name}_pass_through"),
            (run.crossings.pass_through_body + run.crossings.pass_through_wall) as f64,
            Target::equal(0.0),
            "1",
        );
        ctx.check(
            &format!("{name}_contacts_evaluated"),
            run.counters.contacts as f64,
            Target::at_least(1.0),
            "1",
        );
    }
    ctx.check(
        "bed_energy_error_max",
        r.bed.run.energy_error_max,
        Target::at_most(tol.energy),
        "1",
    );
    ctx.check(
        "wall_energy_error_max",
        r.wall.run.energy_error_max,
        Target::at_most(tol.energy),
        "1",
    );
    ctx.check(
        "bed_overlap_max",
        r.bed.run.max_overlap_ratio,
        Target::at_most(tol.overlap),
        "1",
    );
    ctx.check(
        "wall_projectile_rebound_vz_max",
        r.wall.max_vz,
        Target::at_least(0.0),
        "m/s",
    );
    ctx.check(
        "guard_refuses_dt_above_limit",
        if r.guard.refused { 1.0 } else { 0.0 },
        Target::equal(1.0),
        "1",
    );
    ctx.check(
        "guard_error_names_time_step_line",
        if r.guard.named_line { 1.0 } else { 0.0 },
        Target::equal(1.0),
        "1",
    );
    ctx.check(
        "bypassed_guard_bed_tunnelling_detected",
        r.bypass_bed.run.crossings.total() as f64,
        Target::at_least(1.0),
        "1",
    );
    ctx.check(
        "bypassed_guard_wall_tunnelling_detected",
        r.bypass_wall.run.crossings.missed() as f64,
        Target::at_least(1.0),
        "1",
    );
}

/// The time step, its limit and the guard's answers.
fn report_guard(ctx: &mut CaseContext, p: &Params, r: &Impacts) {
    ctx.section("Time step and guard");
    ctx.text(&format!(
        "Shortest contact time t_c = {:.4e} s, stability limit Δt_max = {:.4e} s (= t_c/{:.2}); derived \
         Δt = t_c/{} = {:.4e} s, the projectile moves {:.3e} m = {:.3e} particle sizes per step. \
         Δt = {} Δt_max refused: `{}`. Δt = {} Δt_max = {:.4e} s admitted (projectile path per step \
         {:.3e} particle sizes).",
        r.info.contact_time,
        r.info.stability_limit,
        r.info.contact_time / r.info.stability_limit,
        p.steps_per_contact,
        r.info.dt,
        p.speed * r.info.dt,
        p.speed * r.info.dt / (0.9 * p.spacing),
        p.refused_factor,
        r.guard.refusal,
        p.admitted_factor,
        r.guard.admitted_dt,
        p.speed * r.guard.admitted_dt / (0.9 * p.spacing),
    ));
}

/// The runs table.
fn report_runs(ctx: &mut CaseContext, r: &Impacts) -> Result<(), SuiteError> {
    ctx.section("Runs");
    let row = |name: &str, run: &ImpactRun| {
        let c = &run.run.crossings;
        vec![
            name.to_string(),
            format!("{:.3e}", run.dt),
            run.run.steps.to_string(),
            run.run.step_error.clone().unwrap_or_else(|| "none".into()),
            c.missed_body.to_string(),
            c.missed_wall.to_string(),
            c.pass_through_body.to_string(),
            c.pass_through_wall.to_string(),
            run.run.first_crossing.map_or("–".into(), |x| {
                format!(
                    "step {}, body {} through {:?} ({:?})",
                    x.step, x.body, x.obstacle, x.kind
                )
            }),
            format!("{:.3e}", run.run.max_overlap_ratio),
            format!("{:.3e}", run.run.energy_error_max),
            run.run.counters.contacts.to_string(),
            format!(
                "[{:.1}, {:.1}, {:.1}]",
                run.final_velocity.x, run.final_velocity.y, run.final_velocity.z
            ),
        ]
    };
    ctx.table(
        Some("runs"),
        &[
            "run",
            "Δt (s)",
            "steps",
            "step error",
            "missed (body)",
            "missed (wall)",
            "pass-through (body)",
            "pass-through (wall)",
            "first crossing",
            "max overlap/size",
            "max abs(balance)/E0",
            "contact evaluations",
            "projectile final velocity (m/s)",
        ],
        &[
            row("bed, Δt = t_c/N", &r.bed),
            row("wall, Δt = t_c/N", &r.wall),
            row("bed, Δt just below the limit", &r.limit),
            row("bed, guard bypassed", &r.bypass_bed),
            row("wall, guard bypassed", &r.bypass_wall),
        ],
    )?;
    Ok(())
}

/// The projectile's speed and height against time.
fn plot_impacts(ctx: &mut CaseContext, p: &Params, r: &Impacts) -> Result<(), SuiteError> {
    ctx.plot(&Plot {
        name: "projectile_speed".into(),
        title: "Projectile speed during the impacts".into(),
        x_label: "t (ms)".into(),
        y_label: "|v| (m/s)".into(),
        x_log: false,
        y_log: false,
        series: vec![
            Series {
                label: "bed, Δt = t_c/N".into(),
                style: SeriesStyle::Line,
                points: r.bed.speed.clone(),
            },
            Series {
                label: "bed, Δt = 0.99 Δt_max".into(),
                style: SeriesStyle::Line,
                points: r.limit.speed.clone(),
            },
            Series {
                label: "wall, Δt = t_c/N".into(),
                style: SeriesStyle::Line,
                points: r.wall.speed.clone(),
            },
        ],
        caption: format!(
            "A steel box projectile ({:?} m half extents) at {} m/s into a bed of {} rock polyhedra and onto a wall.",
            p.projectile_half_extents,
            p.speed,
            p.bed.iter().product::<usize>()
        ),
    })?;
    ctx.plot(&Plot {
        name: "projectile_height".into(),
        title: "Projectile height".into(),
        x_label: "t (ms)".into(),
        y_label: "z (m)".into(),
        x_log: false,
        y_log: false,
        series: vec![
            Series {
                label: "bed, Δt = t_c/N".into(),
                style: SeriesStyle::Line,
                points: r.bed.height.clone(),
            },
            Series {
                label: "bed, Δt = 0.99 Δt_max".into(),
                style: SeriesStyle::Line,
                points: r.limit.height.clone(),
            },
            Series {
                label: "bed top".into(),
                style: SeriesStyle::Line,
                points: vec![
                    (0.0, p.bed[2] as Real * p.spacing),
                    (p.duration * 1e3, p.bed[2] as Real * p.spacing),
                ],
            },
        ],
        caption: "The projectile's centre of mass; the floor is z = 0.".into(),
    })?;
    Ok(())
}
