//! Throughput of the flat sphere path (`polydem::world::SphereSim`) on 1 and 2 threads (target:
//! ≥ 1.8× its one-thread speed on 2 threads), on the scene `spheres` of `examples/perf_threads.rs` (10^4
//! spheres dropped from a lattice into a box of five walls, `tests/support/bed.rs`) and on the sphere
//! beds (`scenes/sphere_bed_*.toml`).
//!
//! Each scene is warmed up on the flat path (so that the lattice is in contact); then, `--repeat` times,
//! each variant (a thread count and a split of the team's work, `SphereSim::set_team_split`)
//! runs the same steps from the warm state. The variants take turns in stretches of `--interleave`
//! steps, in alternating order, so that each sees the shared host as the others do (by default one
//! stretch: each variant's steps back to back).
//! Printed per variant and round: wall time, process CPU time (all threads), the share of the machine's
//! CPU time the hypervisor stole during the round (a busy host), on several threads the core-to-core
//! round trip right after the round (`polydem::host::core_round_trip_ns`: 41–160 ns or 419–499 ns,
//! as the host placed the two virtual CPUs), particle-steps/s (wall), the load
//! average, the wall time per step of each stage (the step's counters: kick and drift, lists, pair
//! loop, walls and ledger) and whether the final state is bit-identical to the first variant's; then
//! the median and range over the rounds of each variant's speed-up over the first.
//!
//! ```text
//! cargo run --release --example sphere_flat_threads -- [--steps N] [--warm-up N] [--threads 1,2]
//!     [--splits default,fixed,0.2] [--interleave N] [--repeat N]
//!     [--scenes spheres,a_hertz_5ms,b_hertz_200ms,c_linear_5ms] [--driver run|step]
//! ```
//! A split is `default` (`TeamSplit::default()`), `fixed` (`TeamSplit::fixed()`: blocks of equal
//! weight, no middles) or a number: the default with that middle share of the pair loop.
//! Defaults: 1000 steps after a warm-up of 1000, threads 1,2, the default split, 3 repeats, scene
//! `spheres`, the steps run by `SphereSim::run_steps` as the suite's sphere_bed case runs them
//! (`--driver step`: `SphereSim::step` called for each step, each step's team job a rayon broadcast).

#[path = "../tests/support/bed.rs"]
mod bed;

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use polydem::host::{core_round_trip_text, load_average, CpuTicks};
use polydem::scene::load_scene;
use polydem::world::sphere_flat::TeamSplit;
use polydem::world::{SphereSim, StepParams, World};

struct Options {
    steps: usize,
    warm_up: usize,
    threads: Vec<usize>,
    repeat: usize,
    scenes: Vec<String>,
    step_by_step: bool,
    splits: Vec<(String, TeamSplit)>,
    interleave: usize,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        steps: 1000,
        warm_up: 1000,
        threads: vec![1, 2],
        repeat: 3,
        scenes: vec!["spheres".into()],
        step_by_step: false,
        splits: vec![("default".into(), TeamSplit::default())],
        interleave: usize::MAX,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--steps" => o.steps = value()?.parse().map_err(|e| format!("--steps: {e}"))?,
            "--warm-up" => o.warm_up = value()?.parse().map_err(|e| format!("--warm-up: {e}"))?,
            "--repeat" => {
                o.repeat = value()?
                    .parse::<usize>()
                    .map_err(|e| format!("--repeat: {e}"))?
                    .max(1)
            }
            "--threads" => {
                o.threads = value()?
                    .split(',')
                    .map(|t| t.parse().map_err(|e| format!("--threads: {e}")))
                    .collect::<Result<_, _>>()?
            }
            "--scenes" => o.scenes = value()?.split(',').map(str::to_owned).collect(),
            "--splits" => {
                o.splits = value()?
                    .split(',')
                    .map(|name| {
                        let split = match name {
                            "default" => TeamSplit::default(),
                            "fixed" => TeamSplit::fixed(),
                            share => TeamSplit {
                                middle_share: share.parse().map_err(|e| {
                                    format!(
                                        "--splits: default, fixed or a number, not {share}: {e}"
                                    )
                                })?,
                                ..TeamSplit::default()
                            },
                        };
                        Ok((name.to_owned(), split))
                    })
                    .collect::<Result<_, String>>()?
            }
            "--interleave" => {
                o.interleave = value()?
                    .parse::<usize>()
                    .map_err(|e| format!("--interleave: {e}"))?
                    .max(1)
            }
            "--driver" => {
                o.step_by_step = match value()?.as_str() {
                    "run" => false,
                    "step" => true,
                    other => return Err(format!("--driver: run or step, not {other}")),
                }
            }
            _ => return Err(format!("unknown argument {a}")),
        }
    }
    Ok(o)
}

/// The world and step parameters of scene `name`, not yet warmed up.
fn build(name: &str) -> Result<(World, StepParams), String> {
    if name == "spheres" {
        let spec = bed::BedSpec {
            gap: 0.0,
            speed: 1.0,
            hull_shapes: 1,
            ..bed::BedSpec::rocks([25, 25, 16], 1, 20261121)
        };
        let b = bed::build(&spec);
        let mut params = b.params;
        params.energy_ledger = false;
        return Ok((b.world, params));
    }
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/sphere_bed_{name}.toml"));
    let mut sim = load_scene(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    sim.params.energy_ledger = false;
    Ok((sim.world, sim.params))
}

/// Process CPU time (user + system, all threads).
fn cpu_time() -> Duration {
    // SAFETY: getrusage only writes into the struct we pass.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, t.tv_usec as u32 * 1000);
    tv(usage.ru_utime) + tv(usage.ru_stime)
}

/// The bits of every sphere's state.
fn state_bits(sim: &SphereSim) -> Vec<u64> {
    (0..sim.len())
        .flat_map(|i| {
            let (x, v, l) = (sim.position(i), sim.velocity(i), sim.angular_momentum(i));
            [x.x, x.y, x.z, v.x, v.y, v.z, l.x, l.y, l.z]
        })
        .map(f64::to_bits)
        .collect()
}

/// One way of running the scene: a thread count and a middle share, with its simulation and pool and
/// what its timed steps cost so far.
struct Variant {
    threads: usize,
    split: String,
    sim: SphereSim,
    pool: rayon::ThreadPool,
    wall: Duration,
    cpu: Duration,
    stages: [Duration; 4],
    rebuilds: u64,
}

impl Variant {
    fn label(&self, splits: usize) -> String {
        match splits {
            1 => format!("{} thread(s)", self.threads),
            _ => format!("{} thread(s) split {}", self.threads, self.split),
        }
    }

    /// Runs `steps` more steps and adds their costs.
    fn run(&mut self, steps: usize, step_by_step: bool) -> Result<(), String> {
        let (cpu0, t) = (cpu_time(), Instant::now());
        let (sim, stages, rebuilds) = (&mut self.sim, &mut self.stages, &mut self.rebuilds);
        let mut add = |c: &polydem::world::StepCounters| {
            for (total, d) in stages
                .iter_mut()
                .zip([c.integrate, c.broad, c.narrow, c.accumulate])
            {
                *total += d;
            }
            *rebuilds += c.broad_rebuilds;
        };
        self.pool.install(|| -> Result<(), String> {
            if step_by_step {
                for _ in 0..steps {
                    add(&sim.step().map_err(|e| e.to_string())?.counters);
                }
            } else {
                sim.run_steps(steps as u64, |_, report| {
                    add(&report.counters);
                    ControlFlow::Continue(())
                })
                .map_err(|e| e.to_string())?;
            }
            Ok(())
        })?;
        self.wall += t.elapsed();
        self.cpu += cpu_time() - cpu0;
        Ok(())
    }
}

fn main() -> Result<(), String> {
    let o = parse()?;
    for name in &o.scenes {
        let (world, params) = build(name)?;
        let mut warm = SphereSim::from_world(&world, &params).map_err(|e| e.to_string())?;
        // As the suite's sphere_bed case: no output reads the orientations (the same motion either way).
        warm.set_track_orientation(false);
        for _ in 0..o.warm_up {
            warm.step().map_err(|e| e.to_string())?;
        }
        println!(
            "scene {name}: {} spheres, {} steps after a warm-up of {}, Δt {:.3e} s, in stretches of {}",
            warm.len(),
            o.steps,
            o.warm_up,
            params.dt,
            o.interleave.min(o.steps)
        );
        // Per round, per variant other than the first: its wall time over the first's.
        let mut ratios: Vec<Vec<f64>> = Vec::new();
        for round in 0..o.repeat {
            let mut variants = Vec::new();
            for &threads in &o.threads {
                for (name, split) in &o.splits {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .map_err(|e| e.to_string())?;
                    let mut sim = warm.clone();
                    sim.set_team_split(*split);
                    variants.push(Variant {
                        threads,
                        split: name.clone(),
                        sim,
                        pool,
                        wall: Duration::ZERO,
                        cpu: Duration::ZERO,
                        stages: [Duration::ZERO; 4],
                        rebuilds: 0,
                    });
                }
            }
            let load = load_average();
            let ticks = CpuTicks::now();
            // The variants take turns, stretch by stretch, in alternating order: each sees the host as
            // the others do.
            let (mut done, mut stretch) = (0, 0);
            while done < o.steps {
                let steps = o.interleave.min(o.steps - done);
                let order: Vec<usize> = match stretch % 2 {
                    0 => (0..variants.len()).collect(),
                    _ => (0..variants.len()).rev().collect(),
                };
                for v in order {
                    variants[v].run(steps, o.step_by_step)?;
                }
                done += steps;
                stretch += 1;
            }
            let steal = CpuTicks::now()
                .zip(ticks)
                .and_then(|(now, then)| now.steal_since(&then))
                .map_or("n/a".to_owned(), |s| format!("{:.1} %", 100.0 * s));
            let first_bits = state_bits(&variants[0].sim);
            let first_wall = variants[0].wall.as_secs_f64();
            let mut round_ratios = Vec::new();
            for (k, v) in variants.iter().enumerate() {
                let wall = v.wall.as_secs_f64();
                let per_step = |d: Duration| d.as_secs_f64() * 1e6 / o.steps as f64;
                let rate = v.sim.len() as f64 * o.steps as f64 / wall;
                let same = (k > 0).then(|| state_bits(&v.sim) == first_bits);
                // After the round: which state the host's cores were in (`host::core_round_trip_ns`).
                let round_trip = match v.threads {
                    1 => String::new(),
                    _ => format!(", core round trip {}", v.pool.install(core_round_trip_text)),
                };
                println!(
                    "  round {round}, {}: wall {wall:.3} s, CPU {:.3} s, steal {steal}{round_trip}, {rate:.3e} particle-steps/s, load {load}; µs per step: kick+drift {:.1}, lists {:.1} ({} builds), pairs {:.1}, walls {:.1}{}",
                    v.label(o.splits.len()),
                    v.cpu.as_secs_f64(),
                    per_step(v.stages[0]),
                    per_step(v.stages[1]),
                    v.rebuilds,
                    per_step(v.stages[2]),
                    per_step(v.stages[3]),
                    match same {
                        Some(true) => ", bit-identical to the first",
                        Some(false) => ", DIFFERS from the first",
                        None => "",
                    }
                );
                if k > 0 {
                    round_ratios.push(first_wall / wall);
                }
            }
            ratios.push(round_ratios);
        }
        let labels: Vec<String> = o
            .threads
            .iter()
            .flat_map(|&t| o.splits.iter().map(move |(name, _)| (t, name)))
            .map(|(threads, name)| match o.splits.len() {
                1 => format!("{threads} thread(s)"),
                _ => format!("{threads} thread(s) split {name}"),
            })
            .collect();
        for (k, label) in labels.iter().enumerate().skip(1) {
            let mut of_variant: Vec<f64> = ratios.iter().map(|r| r[k - 1]).collect();
            of_variant.sort_by(|a, b| a.total_cmp(b));
            if let (Some(lo), Some(hi)) = (of_variant.first(), of_variant.last()) {
                println!(
                    "  speed-up of {label} over {}: median {:.3}, range {:.3}–{:.3} over {} rounds",
                    labels[0],
                    of_variant[of_variant.len() / 2],
                    lo,
                    hi,
                    of_variant.len()
                );
            }
        }
    }
    Ok(())
}
