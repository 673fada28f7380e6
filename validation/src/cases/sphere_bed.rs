//! Case `sphere_bed` (issue 7): the sphere-bed penetration of `reference/sphere_bed/` run by polydem from
//! the scene files `scenes/sphere_bed_*.toml`, compared with the recorded YADE 2023.02a and LIGGGHTS 3.8.0
//! outputs of the same scene (same settled bed, same laws, same time step, same sampling).
//!
//! The yardstick is the spread between the two reference codes on the same run: polydem's projectile depth
//! history must stay within the YADE–LIGGGHTS gap of the nearer code, and the impact quantities (peak force,
//! vertical contact impulse, time to lose 90 % of the speed) and the final depth within the tolerances of
//! `validation/cases/sphere_bed.toml`, which quote the yardstick proposed with the recorded runs
//! (`reference/sphere_bed/README.md`). Speed is reported against the recorded wall times of the reference
//! runs (recorded, not re-measured: the codes need not be installed); the speed targets of issue 7 are
//! checked in the full profile only (speed never gates `cargo test`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use polydem::math::Real;
use polydem::scene::load_scene;
use serde::Deserialize;

use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

/// The case (registered in [`crate::cases::registry`]).
pub struct SphereBed;

const NAME: &str = "sphere_bed";

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Variant {
    /// Variant name, as in `reference/sphere_bed/scene.json` and the reference CSV files.
    name: String,
    /// Scene file, relative to the repository root.
    scene: String,
    /// Steps to run (at most the scene's); fewer steps compare the first part of the run.
    steps: Option<u64>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    variants: Vec<Variant>,
    /// Whether the speed targets are checked (full profile only).
    check_speed: bool,
}

/// One code's projectile history: samples every 10 steps.
#[derive(Clone, Debug, Default)]
struct History {
    t: Vec<Real>,
    z: Vec<Real>,
    vz: Vec<Real>,
    fz: Vec<Real>,
}

/// The `# key: value` provenance lines of a recorded output.
#[derive(Clone, Debug, Default)]
struct Recorded {
    history: History,
    date: String,
    machine: String,
    wall_time_s: Real,
    steps: Real,
    particles: Real,
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from(".."))
}

fn fail(msg: String) -> SuiteError {
    SuiteError::case(NAME, msg)
}

/// Reads `reference/<code>/out/<variant>.csv`.
fn read_recorded(path: &Path) -> Result<Recorded, SuiteError> {
    let text = std::fs::read_to_string(path).map_err(SuiteError::io(path))?;
    let mut rec = Recorded::default();
    for line in text.lines().filter(|l| l.starts_with('#')) {
        let body = line.trim_start_matches('#').trim();
        let Some((key, value)) = body.split_once(':') else {
            continue;
        };
        let value = value.trim();
        let number = || {
            value.parse::<Real>().map_err(|_| {
                fail(format!(
                    "{}: {key}: '{value}' is not a number",
                    path.display()
                ))
            })
        };
        match key {
            "date" => rec.date = value.to_owned(),
            "machine" => rec.machine = value.to_owned(),
            "wall_time_s" => rec.wall_time_s = number()?,
            "steps" => rec.steps = number()?,
            "particles" => rec.particles = number()?,
            _ => {}
        }
    }
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let headers = reader.headers().map_err(SuiteError::csv(path))?.clone();
    let col = |name: &str| {
        headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| fail(format!("{}: no column '{name}'", path.display())))
    };
    let (ct, cz, cvz, cfz) = (col("t")?, col("z")?, col("vz")?, col("fz")?);
    for record in reader.records() {
        let record = record.map_err(SuiteError::csv(path))?;
        let get = |c: usize| -> Result<Real, SuiteError> {
            record
                .get(c)
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| fail(format!("{}: bad row {:?}", path.display(), record)))
        };
        rec.history.t.push(get(ct)?);
        rec.history.z.push(get(cz)?);
        rec.history.vz.push(get(cvz)?);
        rec.history.fz.push(get(cfz)?);
    }
    if rec.wall_time_s <= 0.0 || rec.steps <= 0.0 || rec.particles <= 0.0 {
        return Err(fail(format!(
            "{}: the header lacks wall_time_s, steps or particles",
            path.display()
        )));
    }
    Ok(rec)
}

/// CPU time of the calling thread (s), from the scheduler's statistics; `None` where unavailable.
fn thread_cpu_time() -> Option<Real> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: Real = text.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "n/a".into())
}

struct Run {
    history: History,
    z0: Real,
    v0: Real,
    steps: u64,
    particles: usize,
    wall_time_s: Real,
    cpu_time_s: Option<Real>,
    load: String,
    max_overlap_ratio: Real,
}

/// Runs polydem on the variant's scene, sampling the projectile every output interval.
fn run_polydem(variant: &Variant, ctx: &mut CaseContext) -> Result<Run, SuiteError> {
    let path = repo_root().join(&variant.scene);
    let mut sim = load_scene(&path).map_err(|e| fail(e.to_string()))?;
    if let Some(steps) = variant.steps {
        sim.steps = sim.steps.min(steps);
    }
    let projectile = sim
        .world
        .names
        .iter()
        .position(|n| n == "projectile")
        .ok_or_else(|| fail(format!("{}: no body named 'projectile'", path.display())))?;
    let z0 = sim.world.bodies[projectile].position.z;
    let v0 = sim.world.bodies[projectile].velocity.norm();
    let particles = sim.world.bodies.len();
    let mut history = History::default();
    let steps = sim.steps;
    ctx.progress().stage(&variant.name, steps);
    let load = load_average();
    // Single thread: the step's parallel stages run on rayon's current pool, here one of one thread; the
    // CPU time is that of the pool's thread, read inside it.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| fail(format!("one-thread pool: {e}")))?;
    let progress = ctx.progress();
    let (summary, wall_time_s, cpu_time_s) = pool.install(|| {
        let cpu_start = thread_cpu_time();
        let start = Instant::now();
        let summary = sim.run(
            |s| {
                let b = &s.world.bodies[projectile];
                history.t.push(s.world.time);
                history.z.push(b.position.z);
                history.vz.push(b.velocity.z);
                // No loads before the first step: the projectile starts out of contact.
                history
                    .fz
                    .push(s.world.loads.forces.get(projectile).map_or(0.0, |f| f.z));
                Ok(())
            },
            |_, n| {
                if n % 500 == 0 {
                    progress.inc(500);
                }
                Ok(())
            },
        );
        let wall = start.elapsed().as_secs_f64();
        let cpu = match (cpu_start, thread_cpu_time()) {
            (Some(a), Some(b)) if b > a => Some(b - a),
            _ => None,
        };
        (summary, wall, cpu)
    });
    let summary = summary.map_err(|e| fail(format!("{}: {e}", variant.scene)))?;
    Ok(Run {
        history,
        z0,
        v0,
        steps,
        particles,
        wall_time_s,
        cpu_time_s,
        load,
        max_overlap_ratio: summary.max_overlap_ratio,
    })
}

/// The compared quantities of one history over its samples with t ≤ `t_end`.
#[derive(Clone, Copy, Debug)]
struct Metrics {
    final_depth: Real,
    max_depth: Real,
    final_vz: Real,
    peak_force: Real,
    peak_time: Real,
    first_contact: Real,
    slow_time: Real,
    impulse: Real,
}

fn metrics(h: &History, z0: Real, v0: Real, t_end: Real) -> Metrics {
    let n =
        h.t.iter()
            .take_while(|&&t| t <= t_end * (1.0 + 1e-9))
            .count();
    let depth = |i: usize| z0 - h.z[i];
    let (mut peak_force, mut peak_time) = (Real::NEG_INFINITY, Real::NAN);
    let (mut first_contact, mut slow_time) = (Real::NAN, Real::NAN);
    let mut impulse = 0.0;
    let mut max_depth = Real::NEG_INFINITY;
    for i in 0..n {
        if h.fz[i] > peak_force {
            peak_force = h.fz[i];
            peak_time = h.t[i];
        }
        // The reference outputs carry round-off of the gravity subtraction (~1e-16 N) before contact.
        if first_contact.is_nan() && h.fz[i] > 1e-6 {
            first_contact = h.t[i];
        }
        if slow_time.is_nan() && h.vz[i].abs() < 0.1 * v0 {
            slow_time = h.t[i];
        }
        if i > 0 {
            impulse += 0.5 * (h.fz[i] + h.fz[i - 1]) * (h.t[i] - h.t[i - 1]);
        }
        max_depth = max_depth.max(depth(i));
    }
    Metrics {
        final_depth: depth(n - 1),
        max_depth,
        final_vz: h.vz[n - 1],
        peak_force,
        peak_time,
        first_contact,
        slow_time,
        impulse,
    }
}

/// Largest |z_a − z_b| over the common samples with t ≤ t_end (same sampling steps in every code).
fn max_gap(a: &History, b: &History, t_end: Real) -> Result<Real, SuiteError> {
    let mut gap: Real = 0.0;
    for i in 0..a.t.len().min(b.t.len()) {
        if a.t[i] > t_end * (1.0 + 1e-9) {
            break;
        }
        if (a.t[i] - b.t[i]).abs() > 1e-6 * a.t[i].max(1e-12) {
            return Err(fail(format!(
                "sample {i}: times differ ({} s vs {} s); the codes must sample the same steps",
                a.t[i], b.t[i]
            )));
        }
        gap = gap.max((a.z[i] - b.z[i]).abs());
    }
    Ok(gap)
}

fn rel(a: Real, b: Real) -> Real {
    (a - b).abs() / (0.5 * (a.abs() + b.abs()))
}

impl Case for SphereBed {
    fn name(&self) -> &'static str {
        NAME
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/sphere_bed.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(NAME, profile)?;
        let impact_tol = data.tolerance(NAME, "impact_rel")?.value;
        let depth_tol = data.tolerance(NAME, "final_depth_rel")?.value;
        let liggghts_target = data.tolerance(NAME, "speed_over_liggghts")?.value;
        let yade_target = data.tolerance(NAME, "speed_over_yade")?.value;
        let mean_diameter = data.reference(NAME, "mean_bed_diameter")?.value;
        let installed = |code: &str| {
            std::env::var_os("PATH")
                .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(code).is_file()))
        };
        ctx.text(&format!(
            "Reference outputs: the recorded runs in `reference/yade/out/` and `reference/liggghts/out/` \
             (produced by `reference/*/run.sh`; dates and machine below). This run does not re-run them \
             (YADE {} here, LIGGGHTS {} here). polydem ran the scene files named below in this process.",
            if installed("yade") { "is installed" } else { "is not installed" },
            if installed("liggghts") { "is installed" } else { "is not installed" },
        ));
        let mut speed_rows = Vec::new();
        let mut summary_rows = Vec::new();
        for variant in &p.variants {
            let yade = read_recorded(
                &repo_root().join(format!("reference/yade/out/{}.csv", variant.name)),
            )?;
            let liggghts = read_recorded(
                &repo_root().join(format!("reference/liggghts/out/{}.csv", variant.name)),
            )?;
            let ours = run_polydem(variant, ctx)?;
            let h = &ours.history;
            let t_end = *h.t.last().ok_or_else(|| fail("no samples".into()))?;
            let recorded_end = *liggghts.history.t.last().unwrap_or(&0.0);
            let m_ours = metrics(h, ours.z0, ours.v0, t_end);
            let m_yade = metrics(&yade.history, ours.z0, ours.v0, t_end);
            let m_lig = metrics(&liggghts.history, ours.z0, ours.v0, t_end);
            let gap_yl = max_gap(&yade.history, &liggghts.history, t_end)?;
            let gap_py = max_gap(h, &yade.history, t_end)?;
            let gap_pl = max_gap(h, &liggghts.history, t_end)?;
            let v = &variant.name;
            ctx.section(&format!("{v} (t ≤ {:.4} ms)", t_end * 1e3));
            let window = if t_end < recorded_end * (1.0 - 1e-9) {
                format!(
                    "This profile runs the first {} of the recorded {} steps (t ≤ {:.4} ms); every \
                     quantity below is taken over that window in all three codes.",
                    ours.steps,
                    liggghts.steps,
                    t_end * 1e3
                )
            } else {
                format!("The whole recorded run ({} steps).", ours.steps)
            };
            ctx.text(&format!(
                "Scene `{}`. {window} Largest overlap in polydem's run: {:.3} of the smaller particle's \
                 diameter.",
                variant.scene, ours.max_overlap_ratio
            ));
            let row = |q: &str, unit: &str, f: &dyn Fn(&Metrics) -> Real, scale: Real| {
                let (o, y, l) = (f(&m_ours) * scale, f(&m_yade) * scale, f(&m_lig) * scale);
                vec![
                    format!("{q} [{unit}]"),
                    CaseContext::fmt(o),
                    CaseContext::fmt(y),
                    CaseContext::fmt(l),
                    format!("{:.2} %", 100.0 * rel(o, y)),
                    format!("{:.2} %", 100.0 * rel(o, l)),
                    format!("{:.2} %", 100.0 * rel(y, l)),
                ]
            };
            let rows = vec![
                row("final depth", "mm", &|m| m.final_depth, 1e3),
                row("max depth", "mm", &|m| m.max_depth, 1e3),
                row("final vertical velocity", "m/s", &|m| m.final_vz, 1.0),
                row("peak contact force", "N", &|m| m.peak_force, 1.0),
                row("time of peak force", "ms", &|m| m.peak_time, 1e3),
                row("first contact", "ms", &|m| m.first_contact, 1e3),
                row("speed below 10 % of v0 at", "ms", &|m| m.slow_time, 1e3),
                row("vertical contact impulse", "N s", &|m| m.impulse, 1.0),
                vec![
                    "max depth-history gap [mean bed diameters]".into(),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    CaseContext::fmt(gap_py / mean_diameter),
                    CaseContext::fmt(gap_pl / mean_diameter),
                    CaseContext::fmt(gap_yl / mean_diameter),
                ],
            ];
            ctx.table(
                Some(&format!("{v}_table")),
                &[
                    "quantity",
                    "polydem",
                    "YADE",
                    "LIGGGHTS",
                    "polydem–YADE",
                    "polydem–LIGGGHTS",
                    "YADE–LIGGGHTS (yardstick)",
                ],
                &rows,
            )?;

            // Checks against the nearer code.
            let nearer = |f: &dyn Fn(&Metrics) -> Real| {
                rel(f(&m_ours), f(&m_yade)).min(rel(f(&m_ours), f(&m_lig)))
            };
            ctx.check(
                &format!("{v}_depth_gap_to_nearer_code"),
                gap_py.min(gap_pl) / mean_diameter,
                Target::at_most(gap_yl / mean_diameter),
                "mean bed diameters (bound: YADE–LIGGGHTS gap)",
            );
            for (metric, f) in [
                (
                    "peak_force",
                    &(|m: &Metrics| m.peak_force) as &dyn Fn(&Metrics) -> Real,
                ),
                ("contact_impulse", &|m: &Metrics| m.impulse),
                ("slow_down_time", &|m: &Metrics| m.slow_time),
            ] {
                ctx.check(
                    &format!("{v}_{metric}_rel_to_nearer_code"),
                    nearer(f),
                    Target::at_most(impact_tol),
                    "1",
                );
            }
            ctx.check(
                &format!("{v}_final_depth_rel_to_nearer_code"),
                nearer(&|m| m.final_depth),
                Target::at_most(depth_tol.max(rel(m_yade.final_depth, m_lig.final_depth))),
                "1 (bound: max of the tolerance and the YADE–LIGGGHTS spread)",
            );
            summary_rows.push(vec![
                v.clone(),
                format!("{:.3}", m_ours.final_depth * 1e3),
                format!("{:.3}", m_yade.final_depth * 1e3),
                format!("{:.3}", m_lig.final_depth * 1e3),
                format!("{:.3}", m_ours.final_vz),
                format!("{:.3}", m_yade.final_vz),
                format!("{:.3}", m_lig.final_vz),
                format!("{:.2}", m_ours.peak_force),
                format!("{:.2}", m_yade.peak_force),
                format!("{:.2}", m_lig.peak_force),
            ]);

            // Plots.
            let series = |hist: &History, label: &str, f: &dyn Fn(usize) -> Real| Series {
                label: label.into(),
                style: SeriesStyle::Line,
                points: (0..hist.t.len())
                    .take_while(|&i| hist.t[i] <= t_end * (1.0 + 1e-9))
                    .map(|i| (hist.t[i] * 1e3, f(i)))
                    .collect(),
            };
            let z0 = ours.z0;
            for (quantity, y_label, pick) in [
                (
                    "depth",
                    "depth z0 − z (mm)",
                    &(|hist: &History, i: usize| (z0 - hist.z[i]) * 1e3)
                        as &dyn Fn(&History, usize) -> Real,
                ),
                (
                    "velocity",
                    "vertical velocity (m/s)",
                    &|hist: &History, i: usize| hist.vz[i],
                ),
                (
                    "force",
                    "vertical contact force (N)",
                    &|hist: &History, i: usize| hist.fz[i],
                ),
            ] {
                ctx.plot(&Plot {
                    name: format!("{v}_{quantity}"),
                    title: format!("{v}: projectile {quantity}"),
                    x_label: "t (ms)".into(),
                    y_label: y_label.into(),
                    x_log: false,
                    y_log: false,
                    series: vec![
                        series(h, "polydem", &|i| pick(h, i)),
                        series(&yade.history, "YADE 2023.02a (recorded)", &|i| {
                            pick(&yade.history, i)
                        }),
                        series(&liggghts.history, "LIGGGHTS 3.8.0 (recorded)", &|i| {
                            pick(&liggghts.history, i)
                        }),
                    ],
                    caption: format!(
                        "Projectile {quantity} against time, the three codes overlaid (YADE reports the \
                         velocity at the half step)."
                    ),
                })?;
            }

            // Speed: particle-steps per second over the stepping loop.
            let ours_rate = ours.particles as Real * ours.steps as Real / ours.wall_time_s;
            let rate = |r: &Recorded| r.particles * r.steps / r.wall_time_s;
            let (yade_rate, lig_rate) = (rate(&yade), rate(&liggghts));
            speed_rows.push(vec![
                v.clone(),
                "polydem (this run)".into(),
                format!("{}", ours.steps),
                format!("{:.2}", ours.wall_time_s),
                ours.cpu_time_s.map_or("n/a".into(), |c| format!("{c:.2}")),
                format!("{:.3e}", ours_rate),
                format!(
                    "{}; load average {}",
                    crate::provenance::utc_now(),
                    ours.load
                ),
            ]);
            for (code, r) in [
                ("YADE (recorded)", &yade),
                ("LIGGGHTS (recorded)", &liggghts),
            ] {
                speed_rows.push(vec![
                    v.clone(),
                    code.into(),
                    format!("{}", r.steps),
                    format!("{:.2}", r.wall_time_s),
                    "n/a".into(),
                    format!("{:.3e}", rate(r)),
                    format!("{}; {}", r.date, r.machine),
                ]);
            }
            speed_rows.push(vec![
                v.clone(),
                "ratio polydem / LIGGGHTS, polydem / YADE".into(),
                String::new(),
                String::new(),
                String::new(),
                format!("{:.3}, {:.3}", ours_rate / lig_rate, ours_rate / yade_rate),
                String::new(),
            ]);
            if p.check_speed {
                ctx.check(
                    &format!("{v}_speed_over_liggghts"),
                    ours_rate / lig_rate,
                    Target::at_least(liggghts_target),
                    "1 (particle-steps/s, wall time; LIGGGHTS recorded)",
                );
                ctx.check(
                    &format!("{v}_speed_over_yade"),
                    ours_rate / yade_rate,
                    Target::at_least(yade_target),
                    "1 (particle-steps/s, wall time; YADE recorded)",
                );
            }
        }
        ctx.section("Summary");
        ctx.table(
            Some("summary"),
            &[
                "variant",
                "final depth polydem [mm]",
                "YADE",
                "LIGGGHTS",
                "final v_z polydem [m/s]",
                "YADE",
                "LIGGGHTS",
                "peak force polydem [N]",
                "YADE",
                "LIGGGHTS",
            ],
            &summary_rows,
        )?;
        ctx.section("Speed (single thread)");
        ctx.text(
            "Particle-steps per second = particles × steps / wall time of the stepping loop. The YADE and \
             LIGGGHTS figures are **recorded** (the wall times in the headers of their output files, with \
             the date and the load of the machine then), not measured in this run; polydem's wall time is \
             measured here, with its thread's CPU time beside it. The machine is shared (2 cores, load \
             averages of 6–11 were seen), so wall-time ratios between runs at different moments carry an \
             uncertainty of up to a factor of two or three.",
        );
        ctx.table(
            Some("speed"),
            &[
                "variant",
                "code",
                "steps",
                "wall time [s]",
                "CPU time [s]",
                "particle-steps/s",
                "when, machine",
            ],
            &speed_rows,
        )?;
        Ok(())
    }
}
