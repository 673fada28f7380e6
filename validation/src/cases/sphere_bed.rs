//! Case `sphere_bed` (issue 7): the sphere-bed penetration of `reference/sphere_bed/` run by polydem from
//! the scene files `scenes/sphere_bed_*.toml`, compared with the recorded YADE 2023.02a and LIGGGHTS 3.8.0
//! outputs of the same scene (same settled bed, same laws, same time step, same sampling).
//!
//! The yardstick is the spread between the two reference codes on the same run: polydem's projectile depth
//! history must stay within the YADE–LIGGGHTS gap of the nearer code, and the impact quantities (peak force,
//! vertical contact impulse, time to lose 90 % of the speed) and the final depth within the tolerances of
//! `validation/cases/sphere_bed.toml`, which quote the yardstick proposed with the recorded runs
//! (`reference/sphere_bed/README.md`). The quick profile compares with the recorded outputs only (the
//! codes need not be installed) and reports speed against the recorded wall times. The full profile
//! re-runs each reference code that is on the PATH (`reference/<code>/run.sh VARIANT` with `OUT_DIR`
//! under the case's output directory, never over the recorded files, right after polydem's run of the same
//! variant), compares polydem with the fresh runs as well as with the recorded ones, and takes the fresh
//! wall times for the speed rows; a code that is not installed is said so on the page and on standard
//! error, and its recorded run stands in. The speed targets of issue 7 are checked in the full profile only
//! (speed never gates `cargo test`): against each reference code as the median over `speed_rounds` rounds
//! of timed runs (polydem, then the codes), and two threads against one as the median over the same
//! one-thread runs, each followed by the same run on two threads.

use crate::provenance::workspace_root;
use crate::stats::relative_difference;
use std::path::Path;
use std::time::Instant;

use polydem::host::{core_round_trip_text, load_average, thread_cpu_time, CpuTicks};
use polydem::math::Real;
use polydem::scene::{load_scene, RunObserver, Simulation, StepPath};
use serde::Deserialize;

use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

use super::projectile_history::{self, History, Metrics, Quantity, QUANTITIES};

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
    /// Whether the reference codes are re-run when installed (full profile only).
    rerun_references: bool,
    /// Rounds of timed runs (polydem, then each re-run reference code) per variant behind the speed
    /// ratios: the first round is the compared runs, the others are timed only; each ratio is the median
    /// of the rounds' (default 1: the compared runs alone).
    #[serde(default = "one")]
    speed_rounds: usize,
}

fn one() -> usize {
    1
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

/// Whether `code` is an executable on the PATH.
fn installed(code: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(code).is_file()))
}

/// Re-runs `reference/<code>/run.sh VARIANT` with its outputs in `dir` (at the priority of this process:
/// `NICE=0`) and reads the fresh output.
fn rerun_reference(code: &str, variant: &str, dir: &Path) -> Result<Recorded, SuiteError> {
    std::fs::create_dir_all(dir).map_err(SuiteError::io(dir))?;
    let script = workspace_root().join(format!("reference/{code}/run.sh"));
    let output = std::process::Command::new("sh")
        .arg(&script)
        .arg(variant)
        .env("OUT_DIR", dir)
        .env("NICE", "0")
        .output()
        .map_err(SuiteError::io(&script))?;
    if !output.status.success() {
        let tail = |b: &[u8]| {
            let text = String::from_utf8_lossy(b);
            let lines: Vec<&str> = text.lines().collect();
            lines[lines.len().saturating_sub(10)..].join("\n")
        };
        return Err(fail(format!(
            "{} {variant} failed ({}): {}\n{}",
            script.display(),
            output.status,
            tail(&output.stdout),
            tail(&output.stderr)
        )));
    }
    read_recorded(&dir.join(format!("{variant}.csv")))
}

struct Run {
    history: History,
    z0: Real,
    v0: Real,
    steps: u64,
    particles: usize,
    wall_time_s: Real,
    cpu_time_s: Option<Real>,
    /// The load average before the run and the share of the machine's CPU time the hypervisor stole
    /// during it, as the speed rows print them.
    load: String,
    max_overlap_ratio: Real,
}

/// Runs polydem on the variant's scene on a pool of `threads` threads, sampling the projectile every
/// output interval.
fn run_polydem(
    variant: &Variant,
    ctx: &mut CaseContext,
    threads: usize,
) -> Result<Run, SuiteError> {
    let path = workspace_root().join(&variant.scene);
    let mut sim = load_scene(&path).map_err(|e| fail(e.to_string()))?;
    if let Some(steps) = variant.steps {
        sim.steps = sim.steps.min(steps);
    }
    // The case compares trajectories and speed; YADE and LIGGGHTS keep no energy ledger, so neither does
    // this run (bodies and forces are the same bits with it: `tests/world_sphere_fast_paths.rs`), which
    // lets the pipeline take the flat sphere layout, as `polydem run` of the scene with
    // `energy_ledger = false` does.
    sim.params.energy_ledger = false;
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
    let stage = if threads == 1 {
        variant.name.clone()
    } else {
        format!("{} ({threads} threads)", variant.name)
    };
    ctx.progress().stage(&stage, steps);
    let load = load_average();
    // The step's parallel stages run on rayon's current pool, here one of `threads` threads; the CPU time
    // is that of the thread that runs the loop, read inside the pool (all of it with one thread).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| fail(format!("pool of {threads} thread(s): {e}")))?;
    let progress = ctx.progress();
    let ticks = CpuTicks::now();
    let (max_overlap_ratio, wall_time_s, cpu_time_s, round_trips) = pool.install(|| {
        // On two threads: the state of the host's cores just before and after the run
        // (`host::core_round_trip_ns`), read outside the timed loop.
        let before = (threads > 1).then(core_round_trip_text);
        let cpu_start = thread_cpu_time();
        let start = Instant::now();
        let mut reported = 0;
        let max_overlap = run_steps(&mut sim, projectile, &mut history, &mut |n| {
            if n >= reported + 500 {
                progress.inc(n - reported);
                reported = n;
            }
        });
        let wall = start.elapsed().as_secs_f64();
        let cpu = match (cpu_start, thread_cpu_time()) {
            (Some(a), Some(b)) if b > a => Some(b - a),
            _ => None,
        };
        let after = before.is_some().then(core_round_trip_text);
        (max_overlap, wall, cpu, before.zip(after))
    });
    // A busy host slows a run on two threads more than one on one: each step waits for both.
    let load = match CpuTicks::now()
        .zip(ticks)
        .and_then(|(now, then)| now.steal_since(&then))
    {
        Some(steal) => format!("{load}; host steal {:.1} %", 100.0 * steal),
        None => load,
    };
    let load = match round_trips {
        Some((before, after)) => format!("{load}; core round trip {before} / {after}"),
        None => load,
    };
    let max_overlap_ratio =
        max_overlap_ratio.map_err(|e| fail(format!("{}: {e}", variant.scene)))?;
    Ok(Run {
        history,
        z0,
        v0,
        steps,
        particles,
        wall_time_s,
        cpu_time_s,
        load,
        max_overlap_ratio,
    })
}

/// The steps of `sim` from its world's step to its end, sampling the projectile at the start and every
/// output interval (and after the last step), through the run `polydem run` uses
/// ([`Simulation::run_observed`]): the pipeline takes the flat sphere layout for a world of free spheres
/// with the ledger off (the same bits as the general step, `tests/pinned_bits.rs`). `on_step` gets the
/// number of steps done. Returns the largest overlap ratio of any step.
fn run_steps(
    sim: &mut Simulation,
    projectile: usize,
    history: &mut History,
    on_step: &mut (dyn FnMut(u64) + Send),
) -> Result<Real, String> {
    let mut samples = ProjectileSamples {
        projectile,
        output_every: sim.output_every,
        last: sim.steps,
        history,
        on_step,
    };
    let summary = sim.run_observed(&mut samples).map_err(|e| e.to_string())?;
    if summary.path != StepPath::FlatSpheres {
        eprintln!("sphere_bed: the general step");
    }
    Ok(summary.max_overlap_ratio)
}

/// The projectile's height, vertical velocity and vertical force at every output step of a run.
struct ProjectileSamples<'a> {
    projectile: usize,
    output_every: u64,
    last: u64,
    history: &'a mut History,
    on_step: &'a mut (dyn FnMut(u64) + Send),
}

impl RunObserver for ProjectileSamples<'_> {
    fn wants_state(&self, n: u64) -> bool {
        n.is_multiple_of(self.output_every) || n == self.last
    }

    fn observe(&mut self, s: &Simulation, _: u64) -> std::io::Result<()> {
        let b = &s.world.bodies[self.projectile];
        // No loads before the first step: the projectile starts out of contact.
        let fz = s
            .world
            .loads
            .forces
            .get(self.projectile)
            .map_or(0.0, |f| f.z);
        let h = &mut *self.history;
        h.t.push(s.world.time);
        h.z.push(b.position.z);
        h.vz.push(b.velocity.z);
        h.fz.push(fz);
        Ok(())
    }

    fn progress(&mut self, n: u64) {
        (self.on_step)(n);
    }

    fn reads_contacts(&self, _: u64) -> bool {
        false
    }
}

/// The metrics of `code`'s history up to `t_end` (an error names the code when it has no samples).
fn metrics(
    code: &str,
    h: &History,
    z0: Real,
    v0: Real,
    t_end: Real,
) -> Result<Metrics, SuiteError> {
    projectile_history::metrics(h, z0, v0, t_end)
        .ok_or_else(|| fail(format!("{code}: no sample at or before t = {t_end} s")))
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

/// The rows of a comparison table: each quantity for polydem, YADE and LIGGGHTS (in that order in
/// `metrics`) with the three pairwise relative differences, then the depth-history gaps (`gaps`: polydem–YADE,
/// polydem–LIGGGHTS, YADE–LIGGGHTS, in mean bed diameters).
fn comparison_rows(metrics: [&Metrics; 3], gaps: [Real; 3]) -> Vec<Vec<String>> {
    let row = |q: &Quantity| {
        let [o, y, l] = metrics.map(|m| q.of(m));
        vec![
            q.heading(),
            CaseContext::fmt(o),
            CaseContext::fmt(y),
            CaseContext::fmt(l),
            format!("{:.2} %", 100.0 * relative_difference(o, y)),
            format!("{:.2} %", 100.0 * relative_difference(o, l)),
            format!("{:.2} %", 100.0 * relative_difference(y, l)),
        ]
    };
    let mut gap_row = vec![
        "max depth-history gap [mean bed diameters]".to_owned(),
        "-".into(),
        "-".into(),
        "-".into(),
    ];
    gap_row.extend(gaps.map(CaseContext::fmt));
    let mut rows: Vec<Vec<String>> = QUANTITIES.iter().map(row).collect();
    rows.push(gap_row);
    rows
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
        let threads_target = data.tolerance(NAME, "two_threads_over_one")?.value;
        let mean_diameter = data.reference(NAME, "mean_bed_diameter")?.value;
        let rerun = |code: &str| p.rerun_references && installed(code);
        let rerun_dir = match ctx.output_dir()? {
            Some(dir) => dir.join("rerun"),
            None => std::env::temp_dir().join(format!("polydem-sphere-bed-{}", std::process::id())),
        };
        let mut intro = String::from(
            "Reference outputs: the recorded runs in `reference/yade/out/` and `reference/liggghts/out/` \
             (produced by `reference/*/run.sh`; dates and machine below). polydem ran the scene files named \
             below in this process.",
        );
        for (code, label) in [("yade", "YADE"), ("liggghts", "LIGGGHTS")] {
            let date = read_recorded(&workspace_root().join(format!(
                "reference/{code}/out/{}.csv",
                p.variants.first().map_or("", |v| v.name.as_str())
            )))
            .map(|r| r.date)
            .unwrap_or_else(|_| "unknown date".into());
            let line = if rerun(code) {
                format!(
                    "{label} is installed: re-run in this suite run, right after polydem's run of each \
                     variant, into `sphere_bed/rerun/{code}/` of the report directory (the recorded runs \
                     are compared too)."
                )
            } else if p.rerun_references {
                format!("{code} not installed: compared against recorded runs of {date}.")
            } else {
                format!(
                    "{label}: compared against recorded runs of {date} (this profile does not re-run the \
                     reference codes; {code} {} here).",
                    if installed(code) { "is installed" } else { "is not installed" }
                )
            };
            if p.rerun_references && !rerun(code) {
                eprintln!("sphere_bed: {line}");
            }
            intro.push_str("\n\n");
            intro.push_str(&line);
        }
        ctx.text(&intro);
        let mut speed_rows = Vec::new();
        let mut summary_rows = Vec::new();
        for variant in &p.variants {
            let yade = read_recorded(
                &workspace_root().join(format!("reference/yade/out/{}.csv", variant.name)),
            )?;
            let liggghts = read_recorded(
                &workspace_root().join(format!("reference/liggghts/out/{}.csv", variant.name)),
            )?;
            let ours = run_polydem(variant, ctx, 1)?;
            // Two threads right after (full profile): the same trajectory, its wall time against the
            // one-thread run's (issue 7: at least 1.8×).
            let mut thread_speedups = Vec::new();
            let mut two_thread = |one: &Run, ctx: &mut CaseContext, rows: &mut Vec<Vec<String>>| {
                let two = run_polydem(variant, ctx, 2)?;
                if two.history.z != one.history.z {
                    return Err(fail(format!(
                        "{}: the two-thread run did not repeat the one-thread trajectory",
                        variant.name
                    )));
                }
                rows.push(vec![
                    variant.name.clone(),
                    format!(
                        "polydem, 2 threads (this run, round {})",
                        thread_speedups.len() + 1
                    ),
                    format!("{}", two.steps),
                    format!("{:.2}", two.wall_time_s),
                    "n/a".into(),
                    format!(
                        "{:.3e}",
                        two.particles as Real * two.steps as Real / two.wall_time_s
                    ),
                    format!(
                        "{}; load average {}",
                        crate::provenance::utc_now(),
                        two.load
                    ),
                ]);
                thread_speedups.push(one.wall_time_s / two.wall_time_s);
                Ok::<(), SuiteError>(())
            };
            let mut thread_rows = Vec::new();
            if p.check_speed {
                two_thread(&ours, ctx, &mut thread_rows)?;
            }
            // The reference codes right after polydem, on the same machine in the same suite run.
            let mut fresh: [Option<Recorded>; 2] = [None, None];
            for (slot, code) in fresh.iter_mut().zip(["yade", "liggghts"]) {
                if rerun(code) {
                    eprintln!("sphere_bed: re-running {code} {} ...", variant.name);
                    *slot = Some(rerun_reference(code, &variant.name, &rerun_dir.join(code))?);
                }
            }
            let [fresh_yade, fresh_lig] = fresh;
            let h = &ours.history;
            let t_end = *h.t.last().ok_or_else(|| fail("no samples".into()))?;
            let recorded_end = *liggghts.history.t.last().unwrap_or(&0.0);
            let m_ours = metrics("polydem", h, ours.z0, ours.v0, t_end)?;
            let m_yade = metrics("YADE (recorded)", &yade.history, ours.z0, ours.v0, t_end)?;
            let m_lig = metrics(
                "LIGGGHTS (recorded)",
                &liggghts.history,
                ours.z0,
                ours.v0,
                t_end,
            )?;
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
            let rows = comparison_rows(
                [&m_ours, &m_yade, &m_lig],
                [gap_py, gap_pl, gap_yl].map(|g| g / mean_diameter),
            );
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
                relative_difference(f(&m_ours), f(&m_yade))
                    .min(relative_difference(f(&m_ours), f(&m_lig)))
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
                Target::at_most(
                    depth_tol.max(relative_difference(m_yade.final_depth, m_lig.final_depth)),
                ),
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

            // The fresh runs of this suite run, where the codes are installed.
            if fresh_yade.is_some() || fresh_lig.is_some() {
                let fy = fresh_yade.as_ref().unwrap_or(&yade);
                let fl = fresh_lig.as_ref().unwrap_or(&liggghts);
                let label = |f: &Option<Recorded>, code: &str| {
                    if f.is_some() {
                        format!("{code} (this run)")
                    } else {
                        format!("{code} (recorded: not installed)")
                    }
                };
                let m_fy = metrics("YADE", &fy.history, ours.z0, ours.v0, t_end)?;
                let m_fl = metrics("LIGGGHTS", &fl.history, ours.z0, ours.v0, t_end)?;
                let gap_fyl = max_gap(&fy.history, &fl.history, t_end)?;
                let gap_pfy = max_gap(h, &fy.history, t_end)?;
                let gap_pfl = max_gap(h, &fl.history, t_end)?;
                let same = |f: &Option<Recorded>, r: &Recorded| -> Result<String, SuiteError> {
                    Ok(match f {
                        Some(f) => CaseContext::fmt(
                            max_gap(&f.history, &r.history, t_end)? / mean_diameter,
                        ),
                        None => "-".into(),
                    })
                };
                let mut rows = comparison_rows(
                    [&m_ours, &m_fy, &m_fl],
                    [gap_pfy, gap_pfl, gap_fyl].map(|g| g / mean_diameter),
                );
                rows.push(vec![
                    "max gap to the recorded run of the same code [mean bed diameters]".into(),
                    "-".into(),
                    same(&fresh_yade, &yade)?,
                    same(&fresh_lig, &liggghts)?,
                    "-".into(),
                    "-".into(),
                    "-".into(),
                ]);
                ctx.text(&format!(
                    "Against the reference runs of this suite run ({}, {}):",
                    label(&fresh_yade, "YADE"),
                    label(&fresh_lig, "LIGGGHTS")
                ));
                ctx.table(
                    Some(&format!("{v}_table_this_run")),
                    &[
                        "quantity",
                        "polydem",
                        &label(&fresh_yade, "YADE"),
                        &label(&fresh_lig, "LIGGGHTS"),
                        "polydem–YADE",
                        "polydem–LIGGGHTS",
                        "YADE–LIGGGHTS (yardstick)",
                    ],
                    &rows,
                )?;
                ctx.check(
                    &format!("{v}_depth_gap_to_nearer_code_this_run"),
                    gap_pfy.min(gap_pfl) / mean_diameter,
                    Target::at_most(gap_fyl / mean_diameter),
                    "mean bed diameters (bound: YADE–LIGGGHTS gap; reference codes re-run in this suite run)",
                );
                ctx.check(
                    &format!("{v}_final_depth_rel_to_nearer_code_this_run"),
                    relative_difference(m_ours.final_depth, m_fy.final_depth)
                        .min(relative_difference(m_ours.final_depth, m_fl.final_depth)),
                    Target::at_most(
                        depth_tol.max(relative_difference(m_fy.final_depth, m_fl.final_depth)),
                    ),
                    "1 (bound: max of the tolerance and the YADE–LIGGGHTS spread; this suite run)",
                );
            }

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
                    series: {
                        let mut list = vec![
                            series(h, "polydem", &|i| pick(h, i)),
                            series(&yade.history, "YADE 2023.02a (recorded)", &|i| {
                                pick(&yade.history, i)
                            }),
                            series(&liggghts.history, "LIGGGHTS 3.8.0 (recorded)", &|i| {
                                pick(&liggghts.history, i)
                            }),
                        ];
                        for (f, label) in [
                            (&fresh_yade, "YADE (this run)"),
                            (&fresh_lig, "LIGGGHTS (this run)"),
                        ] {
                            if let Some(f) = f {
                                list.push(series(&f.history, label, &|i| pick(&f.history, i)));
                            }
                        }
                        list
                    },
                    caption: format!(
                        "Projectile {quantity} against time, the three codes overlaid (YADE reports the \
                         velocity at the half step)."
                    ),
                })?;
            }

            // Speed: particle-steps per second over the stepping loop.
            let ours_rate = ours.particles as Real * ours.steps as Real / ours.wall_time_s;
            let rate = |r: &Recorded| r.particles * r.steps / r.wall_time_s;
            let yade_timed = fresh_yade.as_ref().unwrap_or(&yade);
            let lig_timed = fresh_lig.as_ref().unwrap_or(&liggghts);
            let (yade_rate, lig_rate) = (rate(yade_timed), rate(lig_timed));
            // More rounds of timed runs, each polydem then every re-run reference code, so that a ratio is
            // not one moment of a shared machine: the median of the rounds' ratios per code.
            let mut lig_ratios = vec![ours_rate / lig_rate];
            let mut yade_ratios = vec![ours_rate / yade_rate];
            let codes: Vec<&str> = [
                ("yade", fresh_yade.is_some()),
                ("liggghts", fresh_lig.is_some()),
            ]
            .into_iter()
            .filter(|(_, fresh)| *fresh)
            .map(|(code, _)| code)
            .collect();
            if !codes.is_empty() {
                for k in 1..p.speed_rounds {
                    eprintln!(
                        "sphere_bed: timing round {} of {} ({v}) ...",
                        k + 1,
                        p.speed_rounds
                    );
                    let again = run_polydem(variant, ctx, 1)?;
                    two_thread(&again, ctx, &mut thread_rows)?;
                    if again.history.z != ours.history.z {
                        return Err(fail(format!(
                            "{v}: polydem's timing run {} did not repeat the compared run's trajectory",
                            k + 1
                        )));
                    }
                    let again_rate =
                        again.particles as Real * again.steps as Real / again.wall_time_s;
                    speed_rows.push(vec![
                        v.clone(),
                        format!("polydem (this run, round {})", k + 1),
                        format!("{}", again.steps),
                        format!("{:.2}", again.wall_time_s),
                        again.cpu_time_s.map_or("n/a".into(), |c| format!("{c:.2}")),
                        format!("{again_rate:.3e}"),
                        format!(
                            "{}; load average {}",
                            crate::provenance::utc_now(),
                            again.load
                        ),
                    ]);
                    for code in &codes {
                        // Timed only: its outputs go to a scratch directory, not to the report.
                        let scratch = std::env::temp_dir().join(format!(
                            "polydem-sphere-bed-rounds-{}/{code}{}",
                            std::process::id(),
                            k + 1
                        ));
                        let timed = rerun_reference(code, &variant.name, &scratch)?;
                        let (label, ratios) = if *code == "yade" {
                            ("YADE", &mut yade_ratios)
                        } else {
                            ("LIGGGHTS", &mut lig_ratios)
                        };
                        ratios.push(again_rate / rate(&timed));
                        speed_rows.push(vec![
                            v.clone(),
                            format!("{label} (this run, round {})", k + 1),
                            format!("{}", timed.steps),
                            format!("{:.2}", timed.wall_time_s),
                            "n/a".into(),
                            format!("{:.3e}", rate(&timed)),
                            format!("{}; {}", timed.date, timed.machine),
                        ]);
                    }
                }
            }
            let lig_ratio =
                crate::stats::median(lig_ratios.clone()).unwrap_or(ours_rate / lig_rate);
            let yade_ratio =
                crate::stats::median(yade_ratios.clone()).unwrap_or(ours_rate / yade_rate);
            let yade_source = if fresh_yade.is_some() {
                "this run"
            } else {
                "recorded"
            };
            let lig_source = if fresh_lig.is_some() {
                "this run"
            } else {
                "recorded"
            };
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
            let fresh_rows = [
                fresh_yade.as_ref().map(|r| ("YADE (this run)", r)),
                fresh_lig.as_ref().map(|r| ("LIGGGHTS (this run)", r)),
            ];
            for (code, r) in [
                ("YADE (recorded)", &yade),
                ("LIGGGHTS (recorded)", &liggghts),
            ]
            .into_iter()
            .chain(fresh_rows.into_iter().flatten())
            {
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
            let list = |ratios: &[Real]| {
                ratios
                    .iter()
                    .map(|r| format!("{r:.3}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let rounds_note = if lig_ratios.len() > 1 || yade_ratios.len() > 1 {
                format!(
                    " (medians of the rounds; LIGGGHTS {}; YADE {})",
                    list(&lig_ratios),
                    list(&yade_ratios)
                )
            } else {
                String::new()
            };
            speed_rows.push(vec![
                v.clone(),
                format!(
                    "ratio polydem / LIGGGHTS ({lig_source}), polydem / YADE ({yade_source}){rounds_note}"
                ),
                String::new(),
                String::new(),
                String::new(),
                format!("{:.3}, {:.3}", lig_ratio, yade_ratio),
                String::new(),
            ]);
            if p.check_speed {
                let unit = |ratios: &[Real], code: &str, source: &str| {
                    if ratios.len() > 1 {
                        format!(
                            "1 (particle-steps/s, wall time; median of {} rounds of runs, {code} {source})",
                            ratios.len()
                        )
                    } else {
                        format!("1 (particle-steps/s, wall time; {code} {source})")
                    }
                };
                ctx.check(
                    &format!("{v}_speed_over_liggghts"),
                    lig_ratio,
                    Target::at_least(liggghts_target),
                    &unit(&lig_ratios, "LIGGGHTS", lig_source),
                );
                ctx.check(
                    &format!("{v}_speed_over_yade"),
                    yade_ratio,
                    Target::at_least(yade_target),
                    &unit(&yade_ratios, "YADE", yade_source),
                );
            }
            if let Some(speedup) = crate::stats::median(thread_speedups.clone()) {
                speed_rows.extend(thread_rows);
                speed_rows.push(vec![
                    v.clone(),
                    format!(
                        "ratio polydem 2 threads / 1 thread (median of {} rounds: {})",
                        thread_speedups.len(),
                        thread_speedups
                            .iter()
                            .map(|r| format!("{r:.3}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    String::new(),
                    String::new(),
                    String::new(),
                    format!("{speedup:.3}"),
                    String::new(),
                ]);
                ctx.check(
                    &format!("{v}_two_threads_over_one"),
                    speedup,
                    Target::at_least(threads_target),
                    &format!(
                        "1 (wall time of the one-thread run over the two-thread run right after it; \
                         median of {} rounds)",
                        thread_speedups.len()
                    ),
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
            "Particle-steps per second = particles × steps / wall time of the stepping loop. Rows marked \
             **recorded** take the wall times in the headers of the committed output files (with the date and \
             the load of the machine then); rows marked **this run** are the reference codes re-run by this \
             suite run right after polydem's run of the same variant (full profile, codes installed), and \
             the speed ratios and checks use them when they exist. polydem's wall time is measured here, \
             with its thread's CPU time beside it; it runs without the per-contact energy ledger \
             (`energy_ledger = false`, the same trajectory bit for bit), as YADE and LIGGGHTS keep none, \
             through the run `polydem run` uses (`Simulation::run_observed`, the state handed out every \
             output interval), which takes the flat sphere layout (per-sphere arrays and a half neighbour \
             list; the same bits as the general step). \
             The machine is shared (2 cores, load averages of 6–11 were seen), so wall-time ratios between \
             runs at different moments carry an uncertainty of up to a factor of two or three; within a \
             suite run a single ratio moved by ±10–20 % (2026-11-22), so the full profile times \
             `speed_rounds` rounds per variant (polydem, then each re-run code; rows **round k**) and \
             checks the median of each code's ratios. Each one-thread polydem run of the full profile is followed by the \
             same run on two threads (the same trajectory, checked), and the median of the wall-time \
             ratios is checked against issue 7's 1.8×. Beside each polydem run's load average: the share \
             of the machine's CPU time that the hypervisor gave to other machines during the run \
             (**host steal**, `/proc/stat`); a run on two threads loses more to it than a run on one, \
             since each step waits for both threads. Beside each two-thread run: the time a cache line \
             takes from one of the pool's threads to the other and back, read just before and after the run \
             (**core round trip**, `polydem::host::core_round_trip_ns`). The host moves the machine's two \
             virtual CPUs every few minutes: round trips of 41–60, 94–160 and 419–499 ns were seen on \
             2026-11-27, the last of the size of two dies of the host's processor apart. A two-thread step \
             passes cache lines between the cores at each synchronisation: that day the same 3000 steps of bed a took \
             0.33–0.35 s on two threads at 96–113 ns and 0.42–0.44 s at 419–486 ns (one thread: 0.61–0.65 s \
             throughout), so the two-thread rows hold for the state the run met.",
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
