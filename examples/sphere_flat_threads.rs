//! Throughput of the flat sphere path (`polydem::world::SphereSim`) on 1 and 2 threads (issue 7 target:
//! ≥ 1.8× its one-thread speed on 2 threads), on the scene `spheres` of `examples/perf_threads.rs` (10^4
//! spheres dropped from a lattice into a box of five walls, `tests/support/bed.rs`) and on the sphere
//! beds of issue 7 (`scenes/sphere_bed_*.toml`).
//!
//! Each scene is warmed up on the flat path (so that the lattice is in contact), then the same stretch of
//! steps is run from the warm state once per thread count, alternately, `--repeat` times back to back.
//! Printed per run: wall time, process CPU time (all threads), particle-steps/s (wall), the load average,
//! the wall time per step of each stage (the step's counters: kick and drift, lists, pair loop, walls and
//! ledger) and whether the final state is bit-identical to the first thread count's; then the median and
//! range of the speed-up.
//!
//! ```text
//! cargo run --release --example sphere_flat_threads -- [--steps N] [--warm-up N] [--threads 1,2]
//!     [--repeat N] [--scenes spheres,a_hertz_5ms,b_hertz_200ms,c_linear_5ms] [--driver run|step]
//! ```
//! Defaults: 1000 steps after a warm-up of 1000, threads 1,2, 3 repeats, scene `spheres`, the steps run
//! by `SphereSim::run_steps` as the suite's sphere_bed case runs them (`--driver step`: `SphereSim::step`
//! called for each step, each step's team job a rayon broadcast).

#[path = "../tests/support/bed.rs"]
mod bed;

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use polydem::host::load_average;
use polydem::scene::load_scene;
use polydem::world::{SphereSim, StepParams, World};

struct Options {
    steps: usize,
    warm_up: usize,
    threads: Vec<usize>,
    repeat: usize,
    scenes: Vec<String>,
    step_by_step: bool,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        steps: 1000,
        warm_up: 1000,
        threads: vec![1, 2],
        repeat: 3,
        scenes: vec!["spheres".into()],
        step_by_step: false,
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
            "scene {name}: {} spheres, {} steps after a warm-up of {}, Δt {:.3e} s",
            warm.len(),
            o.steps,
            o.warm_up,
            params.dt
        );
        let mut ratios = Vec::new();
        for round in 0..o.repeat {
            let mut first: Option<(Vec<u64>, f64)> = None;
            for &threads in &o.threads {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .map_err(|e| e.to_string())?;
                let mut sim = warm.clone();
                let load = load_average();
                let (cpu0, t) = (cpu_time(), Instant::now());
                let mut stages = [Duration::ZERO; 4];
                let mut rebuilds = 0;
                let mut add = |c: &polydem::world::StepCounters| {
                    for (total, d) in
                        stages
                            .iter_mut()
                            .zip([c.integrate, c.broad, c.narrow, c.accumulate])
                    {
                        *total += d;
                    }
                    rebuilds += c.broad_rebuilds;
                };
                pool.install(|| -> Result<(), String> {
                    if o.step_by_step {
                        for _ in 0..o.steps {
                            add(&sim.step().map_err(|e| e.to_string())?.counters);
                        }
                    } else {
                        sim.run_steps(o.steps as u64, |_, report| {
                            add(&report.counters);
                            ControlFlow::Continue(())
                        })
                        .map_err(|e| e.to_string())?;
                    }
                    Ok(())
                })?;
                let wall = t.elapsed().as_secs_f64();
                let per_step = |d: Duration| d.as_secs_f64() * 1e6 / o.steps as f64;
                let cpu = (cpu_time() - cpu0).as_secs_f64();
                let bits = state_bits(&sim);
                let same = first.as_ref().map(|(b, _)| *b == bits);
                let rate = sim.len() as f64 * o.steps as f64 / wall;
                println!(
                    "  round {round}, {threads} thread(s): wall {wall:.3} s, CPU {cpu:.3} s, {rate:.3e} particle-steps/s, load {load}; µs per step: kick+drift {:.1}, lists {:.1} ({rebuilds} builds), pairs {:.1}, walls {:.1}{}",
                    per_step(stages[0]),
                    per_step(stages[1]),
                    per_step(stages[2]),
                    per_step(stages[3]),
                    match same {
                        Some(true) => ", bit-identical to the first".to_owned(),
                        Some(false) => ", DIFFERS from the first".to_owned(),
                        None => String::new(),
                    }
                );
                match &first {
                    None => first = Some((bits, wall)),
                    Some((_, wall_1)) => ratios.push(wall_1 / wall),
                }
            }
        }
        ratios.sort_by(|a, b| a.total_cmp(b));
        if let (Some(lo), Some(hi)) = (ratios.first(), ratios.last()) {
            println!(
                "  speed-up of {} thread(s) over {}: median {:.2}, range {:.2}–{:.2} over {} runs",
                o.threads.last().unwrap_or(&1),
                o.threads.first().unwrap_or(&1),
                ratios[ratios.len() / 2],
                lo,
                hi,
                ratios.len()
            );
        }
    }
    Ok(())
}
