//! Polyhedra falling into a box, polydem against YADE's Polyhedra module: the same scene
//! file (`reference/polyhedra_box/scene.toml`: 1000 random convex polyhedra, same vertices, walls, time step
//! and end time) run by `polydem` and by the YADE script `reference/yade/polyhedra_box.py`, which reads that
//! file. YADE uses its own law (normal force proportional to the overlap volume), with the stiffness matched
//! as the reference README explains, so the trajectories are compared as curves, not gated; the gated figure
//! is the cost per step.
//!
//! Speed is compared in CPU seconds of the process (wall time is also reported): on a shared machine the
//! CPU time is the cost of the run, while the wall time also counts the waits for a busy core. The YADE
//! figure is the recorded run (`reference/yade/out/polyhedra_box.csv`, with its date) unless the full
//! profile finds `yade` on the PATH, in which case YADE is re-run in the same suite run.

use crate::provenance::workspace_root;
use std::path::{Path, PathBuf};
use std::time::Instant;

use polydem::math::Real;
use polydem::scene::{load_scene, Simulation};

use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

pub struct PolyhedraBox;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Re-run YADE when it is installed (it takes minutes).
    rerun_yade: bool,
}

/// One monitor row, as the YADE script writes it.
#[derive(Clone, Copy, Debug)]
struct Monitor {
    time: Real,
    mean_z: Real,
    min_z: Real,
    kinetic_energy: Real,
    contacts: Real,
}

/// A run of one code: its monitors and its cost.
struct CodeRun {
    monitors: Vec<Monitor>,
    steps: u64,
    bodies: usize,
    wall_s: Real,
    cpu_s: Real,
    /// Where the figures come from (recorded file and date, or "this run").
    provenance: String,
}

fn fail(msg: String) -> SuiteError {
    SuiteError::case("polyhedra_box", msg)
}

/// CPU time of this process (user + system, all threads), in seconds.
#[cfg(unix)]
fn process_cpu_seconds() -> Real {
    // SAFETY: getrusage only writes into the struct we pass.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let rc = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    if rc != 0 {
        return Real::NAN;
    }
    let seconds = |t: libc::timeval| t.tv_sec as Real + t.tv_usec as Real * 1e-6;
    seconds(usage.ru_utime) + seconds(usage.ru_stime)
}

#[cfg(not(unix))]
fn process_cpu_seconds() -> Real {
    Real::NAN
}

fn monitor(sim: &Simulation) -> Monitor {
    let world = &sim.world;
    let n = world.bodies().len() as Real;
    let mut mean_z = 0.0;
    let mut min_z = Real::INFINITY;
    let mut kinetic = 0.0;
    for b in world.bodies() {
        mean_z += b.position.z / n;
        min_z = min_z.min(b.position.z);
        kinetic += b.translational_kinetic_energy();
    }
    let contacts = world
        .contacts()
        .states()
        .iter()
        .filter(|s| s.is_active())
        .count();
    Monitor {
        time: world.time(),
        mean_z,
        min_z,
        kinetic_energy: kinetic,
        contacts: contacts as Real,
    }
}

fn run_polydem(scene: &Path, ctx: &mut CaseContext) -> Result<(CodeRun, Simulation), SuiteError> {
    let mut sim = load_scene(scene).map_err(|e| fail(e.to_string()))?;
    let mut monitors = Vec::new();
    ctx.progress().stage("polydem", sim.steps);
    let steps = sim.steps;
    let wall0 = Instant::now();
    let cpu0 = process_cpu_seconds();
    let mut progress_steps = 0u64;
    // One worker thread, as YADE runs with -j1: the comparison is single-threaded.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| fail(format!("cannot build a one-thread pool: {e}")))?;
    let summary = {
        let progress = ctx.progress();
        pool.install(|| {
            sim.run(
                |s| {
                    monitors.push(monitor(s));
                    Ok(())
                },
                |_, n| {
                    if n % 200 == 0 || n == steps {
                        progress.inc(n - progress_steps);
                        progress_steps = n;
                    }
                    Ok(())
                },
            )
        })
        .map_err(|e| fail(format!("polydem run of {}: {e}", scene.display())))?
    };
    let cpu_s = process_cpu_seconds() - cpu0;
    let wall_s = wall0.elapsed().as_secs_f64();
    Ok((
        CodeRun {
            monitors,
            steps: summary.steps,
            bodies: sim.world.bodies().len(),
            wall_s,
            cpu_s,
            provenance: "this run".into(),
        },
        sim,
    ))
}

/// Reads the YADE script's CSV: `#` header lines (provenance, timing), then
/// `t,mean_z,min_z,kinetic_energy,contacts,real_interactions` (contacts = overlapping pairs).
fn read_yade(path: &Path) -> Result<CodeRun, SuiteError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| fail(format!("cannot read {}: {e}", path.display())))?;
    let mut wall_s = None;
    let mut cpu_s = None;
    let mut steps = None;
    let mut bodies = None;
    let mut date = String::from("unknown date");
    let mut monitors = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let where_ = || format!("{}:{}", path.display(), i + 1);
        if let Some(header) = line.strip_prefix("# ") {
            if let Some(rest) = header.strip_prefix("wall time (s): ") {
                // "wall time (s): W, cpu time (s): C, particle-steps per cpu second: R"
                let fields: Vec<&str> = rest.split(", ").collect();
                wall_s = fields.first().and_then(|w| w.parse::<Real>().ok());
                cpu_s = fields
                    .get(1)
                    .and_then(|c| c.strip_prefix("cpu time (s): "))
                    .and_then(|c| c.parse::<Real>().ok());
            } else if let Some(rest) = header.strip_prefix("scene: ") {
                // "scene.toml, N polyhedra, dt = D s, S steps"
                for part in rest.split(", ") {
                    if let Some(n) = part.strip_suffix(" polyhedra") {
                        bodies = n.parse::<usize>().ok();
                    } else if let Some(s) = part.strip_suffix(" steps") {
                        steps = s.parse::<u64>().ok();
                    }
                }
            } else if let Some(rest) = header.strip_prefix("date: ") {
                date = rest.split(',').next().unwrap_or(rest).to_string();
            }
            continue;
        }
        if line.starts_with('t') || line.trim().is_empty() {
            continue;
        }
        let v: Vec<Real> = line
            .split(',')
            .map(|f| f.trim().parse::<Real>())
            .collect::<Result<_, _>>()
            .map_err(|e| fail(format!("{}: {e}", where_())))?;
        // t, mean_z, min_z, kinetic_energy, contacts[, real_interactions]
        if v.len() < 5 {
            return Err(fail(format!(
                "{}: expected at least 5 columns, found {}",
                where_(),
                v.len()
            )));
        }
        monitors.push(Monitor {
            time: v[0],
            mean_z: v[1],
            min_z: v[2],
            kinetic_energy: v[3],
            contacts: v[4],
        });
    }
    let missing = |what: &str| fail(format!("{}: no {what} in the header", path.display()));
    Ok(CodeRun {
        monitors,
        steps: steps.ok_or_else(|| missing("step count"))?,
        bodies: bodies.ok_or_else(|| missing("body count"))?,
        wall_s: wall_s.ok_or_else(|| missing("wall time"))?,
        cpu_s: cpu_s.ok_or_else(|| missing("cpu time"))?,
        provenance: format!("recorded {date}"),
    })
}

/// Runs the YADE script into `out_dir` when `yade` is on the PATH; `None` when it is not installed.
fn rerun_yade(root: &Path, out_dir: &Path) -> Result<Option<PathBuf>, SuiteError> {
    let installed = std::process::Command::new("sh")
        .args(["-c", "command -v yade"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !installed {
        return Ok(None);
    }
    let script = root.join("reference/yade/run_polyhedra_box.sh");
    let status = std::process::Command::new("sh")
        .arg(&script)
        .env("OUT_DIR", out_dir)
        .status()
        .map_err(|e| fail(format!("cannot start {}: {e}", script.display())))?;
    if !status.success() {
        return Err(fail(format!("{} failed: {status}", script.display())));
    }
    Ok(Some(out_dir.join("polyhedra_box.csv")))
}

/// The recorded YADE run, committed under `reference/yade/out/`.
fn recorded_yade(root: &Path) -> Result<CodeRun, SuiteError> {
    const RECORDED: &str = "reference/yade/out/polyhedra_box.csv";
    let mut run = read_yade(&root.join(RECORDED))?;
    run.provenance = format!("{} ({RECORDED})", run.provenance);
    Ok(run)
}

/// A monitor plot: file stem, title, y label and the monitored value.
type MonitorPlot = (
    &'static str,
    &'static str,
    &'static str,
    fn(&Monitor) -> Real,
);

fn curve(label: &str, runs: &[Monitor], value: impl Fn(&Monitor) -> Real) -> Series {
    Series {
        label: label.into(),
        style: SeriesStyle::Line,
        points: runs.iter().map(|m| (m.time, value(m))).collect(),
    }
}

impl Case for PolyhedraBox {
    fn name(&self) -> &'static str {
        "polyhedra_box"
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/polyhedra_box.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(self.name(), profile)?;
        let speedup_target = data.tolerance(self.name(), "speedup_vs_yade")?.value;
        let balance_tol = data.tolerance(self.name(), "energy_balance_rel")?.value;
        let root = workspace_root();
        let scene = root.join("reference/polyhedra_box/scene.toml");

        let (ours, sim) = run_polydem(&scene, ctx)?;
        let (yade, yade_note) = yade_run(&p, &root)?;
        if yade.bodies != ours.bodies || yade.steps != ours.steps {
            return Err(fail(format!(
                "YADE run has {} bodies and {} steps, polydem {} and {}: not the same scene",
                yade.bodies, yade.steps, ours.bodies, ours.steps
            )));
        }
        cost_per_step(ctx, &ours, &yade, &yade_note, speedup_target)?;
        energy_ledger(ctx, &sim, balance_tol);
        trajectories(ctx, &sim, &ours, &yade)
    }
}

/// YADE's run of the scene: this run's where YADE is installed and `rerun_yade` asks for it, else the
/// recorded one; with the note the page gives when a re-run was asked for and could not be made.
fn yade_run(p: &Params, root: &Path) -> Result<(CodeRun, String), SuiteError> {
    let mut yade_note = String::new();
    let yade = match p.rerun_yade {
        true => {
            let dir = std::env::temp_dir().join(format!("polydem-yade-box-{}", std::process::id()));
            std::fs::create_dir_all(&dir)
                .map_err(|e| fail(format!("cannot create {}: {e}", dir.display())))?;
            match rerun_yade(root, &dir)? {
                Some(csv) => {
                    let mut run = read_yade(&csv)?;
                    run.provenance = "this run".into();
                    run
                }
                None => {
                    yade_note = "YADE is not installed here: the YADE figures are the recorded run, not this run. ".into();
                    recorded_yade(root)?
                }
            }
        }
        false => recorded_yade(root)?,
    };
    Ok((yade, yade_note))
}

/// The cost of a step in both codes, and the gated ratio of their CPU times.
fn cost_per_step(
    ctx: &mut CaseContext,
    ours: &CodeRun,
    yade: &CodeRun,
    yade_note: &str,
    speedup_target: Real,
) -> Result<(), SuiteError> {
    ctx.section("Cost per step");
    let per_step = |r: &CodeRun, s: Real| s / r.steps as Real;
    let particle_steps = |r: &CodeRun, s: Real| (r.bodies as Real * r.steps as Real) / s;
    let rows: Vec<Vec<String>> = [("polydem", ours), ("YADE 2023.02a -j1", yade)]
        .iter()
        .map(|(name, r)| {
            vec![
                name.to_string(),
                r.provenance.clone(),
                format!("{}", r.steps),
                CaseContext::fmt(r.cpu_s),
                CaseContext::fmt(r.wall_s),
                CaseContext::fmt(per_step(r, r.cpu_s) * 1e6),
                CaseContext::fmt(particle_steps(r, r.cpu_s)),
            ]
        })
        .collect();
    ctx.table(
        Some("timing"),
        &[
            "code",
            "figures from",
            "steps",
            "CPU time (s)",
            "wall time (s)",
            "CPU µs per step",
            "particle-steps per CPU second",
        ],
        &rows,
    )?;
    let speedup = yade.cpu_s / ours.cpu_s;
    let wall_speedup = yade.wall_s / ours.wall_s;
    let contact_steps_ours: Real = ours.monitors.iter().map(|m| m.contacts).sum::<Real>()
        / ours.monitors.len() as Real
        * ours.steps as Real;
    let contact_steps_yade: Real = yade.monitors.iter().map(|m| m.contacts).sum::<Real>()
        / yade.monitors.len() as Real
        * yade.steps as Real;
    ctx.text(&format!(
        "{yade_note}YADE / polydem CPU time per step: **{speedup:.1}×** (wall time: {wall_speedup:.1}×; \
         target ≥ {speedup_target}× from the issue). Mean number of contacts over the run (sampled at the \
         output interval): polydem {:.0}, YADE {:.0}; CPU µs per contact-step: polydem {:.3}, YADE {:.3}.",
        contact_steps_ours / ours.steps as Real,
        contact_steps_yade / yade.steps as Real,
        ours.cpu_s / contact_steps_ours.max(1.0) * 1e6,
        yade.cpu_s / contact_steps_yade.max(1.0) * 1e6,
    ));
    ctx.check(
        "yade_over_polydem_cpu_time",
        speedup,
        Target::at_least(speedup_target),
        "1",
    );

    Ok(())
}

/// The energy ledger of the polydem run and its finite state, gated.
fn energy_ledger(ctx: &mut CaseContext, sim: &Simulation, balance_tol: Real) {
    ctx.section("Energy ledger of the polydem run");
    let e = sim.world.energy();
    let scale = e.mechanical().abs().max(e.translational_kinetic);
    let balance = e.balance.abs() / scale;
    ctx.text(&format!(
        "Elastic normal law (e = 1) with Coulomb friction μ = 0.5: the only dissipation is friction work \
         ({} J). Balance E(t) + dissipated − E(0) = {} J, {} of the mechanical energy {} J. Polyhedra \
         landing flat on a wall carry the known first-order error of the deepest-vertex wall contact \
         (the single_contact_energy case).",
        CaseContext::fmt(e.dissipated_friction),
        CaseContext::fmt(e.balance),
        CaseContext::fmt(balance),
        CaseContext::fmt(e.mechanical()),
    ));
    ctx.check(
        "energy_balance_rel",
        balance,
        Target::at_most(balance_tol),
        "1",
    );
    let nan = sim
        .world
        .bodies()
        .iter()
        .filter(|b| !(b.position.coords.iter().all(|c| c.is_finite())))
        .count();
    ctx.check(
        "non_finite_bodies",
        nan as Real,
        Target::equal(0.0),
        "bodies",
    );
}

/// The monitors of both runs overlaid (not gated: the two laws differ).
fn trajectories(
    ctx: &mut CaseContext,
    sim: &Simulation,
    ours: &CodeRun,
    yade: &CodeRun,
) -> Result<(), SuiteError> {
    ctx.section("Trajectories (not gated: the two laws differ)");
    let plots: [MonitorPlot; 4] = [
        (
            "mean_height",
            "Mean height of the centres of mass",
            "mean z (m)",
            |m| m.mean_z,
        ),
        ("lowest_centre", "Lowest centre of mass", "min z (m)", |m| {
            m.min_z
        }),
        (
            "kinetic_energy",
            "Translational kinetic energy",
            "energy (J)",
            |m| m.kinetic_energy,
        ),
        (
            "contacts",
            "Contacts (overlapping pairs incl. walls)",
            "contacts",
            |m| m.contacts,
        ),
    ];
    for (name, title, y_label, value) in plots {
        ctx.plot(&Plot {
            name: name.into(),
            title: title.into(),
            x_label: "t (s)".into(),
            y_label: y_label.into(),
            x_log: false,
            y_log: false,
            series: vec![
                curve("polydem", &ours.monitors, value),
                curve("YADE (volumetric law)", &yade.monitors, value),
            ],
            caption: format!(
                "Sampled every {} s. YADE: {}.",
                CaseContext::fmt(sim.params.dt * sim.output_every as Real),
                yade.provenance
            ),
        })?;
    }
    Ok(())
}
