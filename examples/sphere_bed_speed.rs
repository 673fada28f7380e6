//! Single-thread speed of the sphere-bed penetration scenes: the quiet-machine re-measurement.
//!
//! Runs the scene files of `validation/src/cases/sphere_bed.rs` (`scenes/sphere_bed_*.toml`: 3000 settled
//! spheres, Hertz–Mindlin or linear spring–dashpot with friction and damping, a steel projectile) for the
//! given number of steps on a rayon pool of one thread, as the suite's speed rows do, and prints per
//! scene: the thread's CPU time and the wall time of the stepping loop, particle-steps/s (CPU and wall),
//! the stage timers and counters of the step, the load average before and after (on several threads
//! also the core-to-core round trip, `polydem::host::core_round_trip_ns`), and a checksum of the
//! final positions and velocities (the bits: two builds that print the same checksum ran the same
//! trajectory).
//!
//! ```text
//! cargo run --release --example sphere_bed_speed -- [--steps N] [--path flat|general] [--threads N]
//!     [--ledger on|off|scene] [--skin M] [--orientation on|off] [--wide on|off] [--driver run|step]
//!     [--check stop|warn|off]
//!     [SCENE.toml ...]
//! ```
//! Default: 5000 steps (0.01 s of the bed) of the three variants a, b, c, on the flat sphere path
//! (`polydem::world::SphereSim`, which runs without the per-contact ledger: `--ledger` is then `off`)
//! on one thread. `--path general` runs the general step (`World::step`; the same bits). `--ledger`
//! overrides the scene's `energy_ledger` key (`scene`: keep it); `--skin` the Verlet skin of the broad
//! phase (m; the candidate list changes, the trajectory does not); `--threads` the size of the pool;
//! `--orientation` whether the flat path turns the spheres' orientations (default off, as the suite's
//! `sphere_bed` case runs it: no output reads them, and positions and velocities are the same bits);
//! `--wide` whether the flat path's passes run in their AVX2 build where the CPU has it (default on;
//! `SphereSim::set_wide_instructions`; the same bits either way); `--driver` how the flat steps are
//! driven: `run` (default) by `SphereSim::run_steps`, as the suite's `sphere_bed` case drives them (on
//! several threads the pool's threads are held for the run), `step` by `SphereSim::step` once per step
//! (each step's team job a rayon broadcast; the same bits, slower on two threads); `--check` the run-time
//! check of the time step (`simulation.time_step_check`; default: the scene's; the same bits either way).

use polydem::host::{core_round_trip_text, load_average, thread_cpu_time};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Instant;

use polydem::scene::{load_scene, RunSummary};
use polydem::world::{SphereSim, TimeStepCheck};

struct Options {
    steps: u64,
    flat: bool,
    threads: usize,
    ledger: Option<bool>,
    skin: Option<f64>,
    orientation: bool,
    wide: bool,
    step_by_step: bool,
    check: Option<TimeStepCheck>,
    scenes: Vec<PathBuf>,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        steps: 5000,
        flat: true,
        threads: 1,
        ledger: None,
        skin: None,
        orientation: false,
        wide: true,
        step_by_step: false,
        check: None,
        scenes: Vec::new(),
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--steps" => o.steps = value()?.parse().map_err(|e| format!("--steps: {e}"))?,
            "--ledger" => {
                o.ledger = match value()?.as_str() {
                    "on" => Some(true),
                    "off" => Some(false),
                    "scene" => None,
                    v => return Err(format!("--ledger: '{v}' is not on, off or scene")),
                }
            }
            "--path" => {
                o.flat = match value()?.as_str() {
                    "flat" => true,
                    "general" => false,
                    v => return Err(format!("--path: '{v}' is not flat or general")),
                }
            }
            "--orientation" => {
                o.orientation = match value()?.as_str() {
                    "on" => true,
                    "off" => false,
                    v => return Err(format!("--orientation: '{v}' is not on or off")),
                }
            }
            "--wide" => {
                o.wide = match value()?.as_str() {
                    "on" => true,
                    "off" => false,
                    v => return Err(format!("--wide: '{v}' is not on or off")),
                }
            }
            "--driver" => {
                o.step_by_step = match value()?.as_str() {
                    "run" => false,
                    "step" => true,
                    v => return Err(format!("--driver: '{v}' is not run or step")),
                }
            }
            "--check" => {
                o.check = Some(match value()?.as_str() {
                    "stop" => TimeStepCheck::Stop,
                    "warn" => TimeStepCheck::Warn,
                    "off" => TimeStepCheck::Off,
                    v => return Err(format!("--check: '{v}' is not stop, warn or off")),
                })
            }
            "--threads" => o.threads = value()?.parse().map_err(|e| format!("--threads: {e}"))?,
            "--skin" => o.skin = Some(value()?.parse().map_err(|e| format!("--skin: {e}"))?),
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            s => o.scenes.push(PathBuf::from(s)),
        }
    }
    if o.scenes.is_empty() {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        for v in ["a_hertz_5ms", "b_hertz_200ms", "c_linear_5ms"] {
            o.scenes
                .push(root.join(format!("scenes/sphere_bed_{v}.toml")));
        }
    }
    Ok(o)
}

fn main() -> anyhow::Result<()> {
    let o = parse().map_err(anyhow::Error::msg)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(o.threads)
        .build()?;
    for path in &o.scenes {
        let mut sim = load_scene(path)?;
        if let Some(on) = o.ledger {
            sim.params.energy_ledger = on;
        }
        if o.flat {
            sim.params.energy_ledger = false;
        }
        if let Some(check) = o.check {
            sim.params.time_step_check = check;
        }
        if let Some(skin) = o.skin {
            sim.world.set_skin(skin);
        }
        sim.steps = sim.steps.min(o.steps);
        let particles = sim.world.bodies().len();
        let load_before = load_average();
        let (summary, wall, cpu, round_trips) = pool.install(|| {
            // On several threads: the state of the host's cores before and after the run.
            let before = (o.threads > 1).then(core_round_trip_text);
            let cpu0 = thread_cpu_time();
            let t = Instant::now();
            let summary = if o.flat {
                run_flat(&mut sim, o.orientation, o.wide, o.step_by_step)
            } else {
                sim.run(|_| Ok(()), |_, _| Ok(()))
                    .map_err(anyhow::Error::from)
            };
            let wall = t.elapsed().as_secs_f64();
            let cpu = cpu0.zip(thread_cpu_time()).map(|(a, b)| b - a);
            let after = before.is_some().then(core_round_trip_text);
            (summary, wall, cpu, before.zip(after))
        });
        let summary = summary?;
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        for b in sim.world.bodies() {
            for x in b.position.iter().chain(b.velocity.iter()) {
                hash = (hash ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3);
            }
        }
        let steps = summary.steps as f64;
        println!(
            "scene {} ({} path{}, {} thread(s))",
            path.display(),
            if o.flat { "flat" } else { "general" },
            if o.flat && !o.wide {
                ", baseline instructions"
            } else {
                ""
            },
            o.threads
        );
        println!(
            "  {} particles, {} steps, ledger {}, time-step check {:?}, skin {:.3e} m: CPU {} s, wall {:.3} s; particle-steps/s {} (CPU), {:.3e} (wall)",
            particles,
            summary.steps,
            if sim.params.energy_ledger { "on" } else { "off" },
            sim.params.time_step_check,
            sim.world.broad_phase().skin(),
            cpu.map_or("n/a".into(), |c| format!("{c:.3}")),
            wall,
            cpu.map_or("n/a".into(), |c| format!("{:.3e}", particles as f64 * steps / c)),
            particles as f64 * steps / wall
        );
        println!(
            "  load average before {load_before}, after {}",
            load_average()
        );
        if let Some((before, after)) = round_trips {
            println!("  core-to-core round trip before {before}, after {after}");
        }
        println!("  final state checksum {hash:016x}");
        for line in summary.counters.to_string().lines() {
            println!("  {line}");
        }
    }
    Ok(())
}

/// The run of `sim` on the flat sphere path, written back into its world at the end.
fn run_flat(
    sim: &mut polydem::scene::Simulation,
    orientation: bool,
    wide: bool,
    step_by_step: bool,
) -> anyhow::Result<RunSummary> {
    let start = Instant::now();
    let mut flat = SphereSim::from_world(&sim.world, &sim.params)?;
    flat.set_track_orientation(orientation);
    if flat.set_wide_instructions(wide) != wide {
        eprintln!("--wide on: this CPU lacks AVX2/BMI, the baseline build runs");
    }
    let mut summary = RunSummary::default();
    let first = flat.step_index() + 1;
    let mut add = |report: &polydem::world::StepReport| {
        summary.counters.merge(&report.counters);
        summary.max_overlap_ratio = summary.max_overlap_ratio.max(report.max_overlap_ratio);
    };
    if step_by_step {
        for _ in first..=sim.steps {
            add(&flat.step()?);
        }
    } else {
        flat.run_steps((sim.steps + 1).saturating_sub(first), |_, report| {
            add(report);
            ControlFlow::Continue(())
        })?;
    }
    flat.write_back(&mut sim.world);
    summary.steps = (sim.steps + 1).saturating_sub(first);
    summary.wall_time = start.elapsed();
    Ok(summary)
}
