//! Throughput of the step on 1 and 2 threads: the quiet-machine re-measurement.
//!
//! Three seeded scenes of 10^4 bodies in a box of five walls (built by `tests/support/bed.rs`, the same
//! builder as the engine tests and `benches/step.rs`), dropped from a tight lattice with random velocities
//! and spins so that they collapse and settle under gravity:
//! - `poly`: 10^4 random convex polyhedra, every body its own hull (14 points on a randomly stretched
//!   sphere, like `reference/polyhedra_box/make_scene.py` but ten times as many bodies);
//! - `poly_projectile`: the same bed struck by a 0.25 m steel sphere at 10 m/s;
//! - `spheres`: 10^4 spheres, same box and law.
//!
//! Each scene is warmed up (so that the lattice is in contact), then the same stretch of steps is run from
//! the warm state once per thread count. Printed per run: wall time, process CPU time (getrusage, all
//! threads), particle-steps/s and contacts/s (wall), the stage timers of the step, the load average, and
//! whether the final state is bit-identical to the first thread count's.
//!
//! ```text
//! cargo run --release --example perf_threads -- [--steps N] [--warm-up N] [--threads 1,2] [--scenes poly,poly_projectile,spheres]
//!     [--min-candidates N] [--min-bodies N] [--repeat N] [--profile]
//! cargo run --release --example perf_threads -- --overhead [--threads 1,2]
//! cargo run --release --example perf_threads -- --write-scenes DIR [--steps N] [--warm-up N] [--scenes ...]
//! ```
//! `--overhead` measures the fork/join cost of a parallel region (behind the thresholds of
//! `src/world/parallel.rs`). `--write-scenes` writes each scene as a scene file `DIR/NAME.toml` for
//! `polydem run` (the initial state, before the warm-up; `end_time` = warm-up + steps): a file of 10^4
//! polyhedra with their own hulls is ~14 MB, too large to keep in the repository, so the scenes are
//! generated on demand from this builder.
//! `--min-candidates` and `--min-bodies` replace the parallel thresholds of the step
//! ([`polydem::world::Parallelism`]; the results are the same bits either way), to re-measure them.
//! `--repeat N` runs the thread counts alternately N times back to back per scene and prints the median,
//! range and best-of-N ratio of the speed-ups (the quiet-machine re-measurement: `--repeat 7`).
//! `--profile` prints per run the CPU time, load balance and costliest chunk of every parallel region and
//! the CPU time of every serial section (`polydem::world::region_profile`).
//! (`scenes/perf/run_threads.sh` runs it with the defaults.)

#[path = "../tests/support/bed.rs"]
mod bed;

use polydem::host::load_average;
use std::time::{Duration, Instant};

use polydem::world::{step, StepCounters, StepParams, StepScratch, World};

struct Options {
    steps: usize,
    warm_up: usize,
    threads: Vec<usize>,
    scenes: Vec<String>,
    min_candidates: Option<usize>,
    min_bodies: Option<usize>,
    /// Measure the fork/join cost of a parallel region instead of running the scenes.
    overhead: bool,
    /// Write the scenes as scene files (TOML) into this folder instead of running them.
    write_scenes: Option<std::path::PathBuf>,
    /// Runs of every thread count per scene, back to back (alternating thread counts).
    repeat: usize,
    /// Print the per-region profile (CPU time per thread, imbalance, serial sections).
    profile: bool,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        steps: 200,
        warm_up: 100,
        threads: vec![1, 2],
        scenes: vec!["poly".into(), "poly_projectile".into(), "spheres".into()],
        min_candidates: None,
        min_bodies: None,
        overhead: false,
        write_scenes: None,
        repeat: 1,
        profile: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--steps" => o.steps = value()?.parse().map_err(|e| format!("--steps: {e}"))?,
            "--warm-up" => o.warm_up = value()?.parse().map_err(|e| format!("--warm-up: {e}"))?,
            "--threads" => {
                o.threads = value()?
                    .split(',')
                    .map(|s| s.parse().map_err(|e| format!("--threads: {e}")))
                    .collect::<Result<_, _>>()?
            }
            "--scenes" => o.scenes = value()?.split(',').map(str::to_owned).collect(),
            "--min-candidates" => {
                o.min_candidates = Some(
                    value()?
                        .parse()
                        .map_err(|e| format!("--min-candidates: {e}"))?,
                )
            }
            "--min-bodies" => {
                o.min_bodies = Some(value()?.parse().map_err(|e| format!("--min-bodies: {e}"))?)
            }
            "--overhead" => o.overhead = true,
            "--profile" => o.profile = true,
            "--repeat" => {
                o.repeat = value()?
                    .parse::<usize>()
                    .map_err(|e| format!("--repeat: {e}"))?
                    .max(1)
            }
            "--write-scenes" => o.write_scenes = Some(value()?.into()),
            _ => return Err(format!("unknown argument {a}")),
        }
    }
    Ok(o)
}

/// The scene `name`, not yet warmed up.
fn build(name: &str) -> Result<bed::Bed, String> {
    let spec = |sphere_every| bed::BedSpec {
        gap: 0.0,
        speed: 1.0,
        // Every polyhedron its own hull.
        hull_shapes: if sphere_every == 1 { 1 } else { 10_000 },
        ..bed::BedSpec::rocks([25, 25, 16], sphere_every, 20261121)
    };
    Ok(match name {
        "poly" => bed::build(&spec(0)),
        "poly_projectile" => {
            let mut b = bed::build(&spec(0));
            // Starts 1 cm above the lattice: it strikes during the warm-up and ploughs on through the
            // measured steps.
            bed::add_projectile(&mut b, 0.125, 7800.0, 0.01, 10.0);
            b
        }
        "spheres" => bed::build(&spec(1)),
        _ => {
            return Err(format!(
                "unknown scene {name} (poly, poly_projectile, spheres)"
            ))
        }
    })
}

/// Process CPU time (user + system, all threads).
fn cpu_time() -> Duration {
    // SAFETY: getrusage only writes into the struct we pass.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let rc = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    if rc != 0 {
        return Duration::ZERO;
    }
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, 1000 * t.tv_usec as u32);
    tv(usage.ru_utime) + tv(usage.ru_stime)
}

/// The bits of every body's state, for the identity check between thread counts.
fn state_bits(w: &World) -> Vec<u64> {
    w.bodies()
        .iter()
        .flat_map(|b| {
            b.position
                .coords
                .iter()
                .chain(b.velocity.iter())
                .chain(b.orientation.coords.iter())
                .chain(b.angular_momentum.iter())
                .map(|x| x.to_bits())
                .collect::<Vec<_>>()
        })
        .collect()
}

fn run(
    world: &World,
    params: &StepParams,
    steps: usize,
    threads: usize,
) -> (World, StepCounters, Duration, Duration) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mut world = world.clone();
    let mut scratch = StepScratch::default();
    let mut counters = StepCounters::default();
    let (cpu0, t0) = (cpu_time(), Instant::now());
    pool.install(|| {
        for _ in 0..steps {
            let r = step(params, &mut world, &mut scratch).expect("step");
            counters.merge(&r.counters);
        }
    });
    let (wall, cpu) = (t0.elapsed(), cpu_time() - cpu0);
    (world, counters, wall, cpu)
}

fn main() {
    let o = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("perf_threads: {e}");
            std::process::exit(2);
        }
    };
    if o.overhead {
        region_overhead(&o.threads);
        return;
    }
    if let Some(dir) = &o.write_scenes {
        if let Err(e) = write_scenes(dir, &o) {
            eprintln!("perf_threads: {e}");
            std::process::exit(1);
        }
        return;
    }
    for name in &o.scenes {
        let mut b = match build(name) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("perf_threads: {e}");
                std::process::exit(2);
            }
        };
        if let Some(n) = o.min_candidates {
            b.params.parallel.min_candidates = n;
        }
        if let Some(n) = o.min_bodies {
            b.params.parallel.min_bodies = n;
        }
        let mut scratch = StepScratch::default();
        for _ in 0..o.warm_up {
            step(&b.params, &mut b.world, &mut scratch).expect("warm-up step");
        }
        let bodies = b.world.bodies().len();
        println!(
            "== {name}: {bodies} bodies, {} steps from the state after {} warm-up steps (dt {:.3e} s; \
             parallel from {} candidates, {} integration units)",
            o.steps, o.warm_up, b.params.dt, b.params.parallel.min_candidates, b.params.parallel.min_bodies
        );
        polydem::world::region_profile::enable(o.profile);
        // Wall times per thread count over the repeats, and the first run's final state.
        let mut walls: Vec<Vec<f64>> = vec![Vec::new(); o.threads.len()];
        let mut reference: Option<(usize, Vec<u64>)> = None;
        let mut identical = true;
        for rep in 0..o.repeat {
            for (ti, &threads) in o.threads.iter().enumerate() {
                let _ = polydem::world::region_profile::take();
                let (w, c, wall, cpu) = run(&b.world, &b.params, o.steps, threads);
                let profile = polydem::world::region_profile::take();
                walls[ti].push(wall.as_secs_f64());
                let ms = |d: Duration| d.as_secs_f64() * 1e3;
                let ps = (bodies * o.steps) as f64 / wall.as_secs_f64();
                let cs = c.contacts as f64 / wall.as_secs_f64();
                let label = if o.repeat > 1 {
                    format!("{name} {threads}t run {}", rep + 1)
                } else {
                    format!("{name} {threads}t")
                };
                println!(
                    "{label}: wall {:.3} s, cpu {:.3} s, {:.3e} particle-steps/s, {:.3e} contacts/s, \
                     {:.0} contacts/step, {:.0} candidates/step, load {}",
                    wall.as_secs_f64(),
                    cpu.as_secs_f64(),
                    ps,
                    cs,
                    c.contacts as f64 / o.steps as f64,
                    (c.body_pairs_tested + c.wall_pairs_tested) as f64 / o.steps as f64,
                    load_average()
                );
                println!(
                    "{label} stages (ms): broad {:.0}, narrow+laws {:.0}, accumulate {:.0}, integrate {:.0}, checks {:.0}; broad rebuilds {}; serial sections {:.0} ms = {:.1} % of the stages",
                    ms(c.broad),
                    ms(c.narrow + c.laws),
                    ms(c.accumulate),
                    ms(c.integrate),
                    ms(c.checks),
                    c.broad_rebuilds,
                    ms(c.serial),
                    100.0 * c.serial.as_secs_f64() / c.total_time().as_secs_f64()
                );
                if o.profile {
                    print_profile(&label, &profile, cpu);
                }
                let bits = state_bits(&w);
                match &reference {
                    None => reference = Some((threads, bits)),
                    Some((t_ref, bits_ref)) => {
                        let same = *bits_ref == bits;
                        identical &= same;
                        println!(
                            "{label} vs {t_ref}t: speed-up {:.2}x (wall, this repeat), final state bit-identical: {}",
                            walls[0][rep] / wall.as_secs_f64(),
                            if same { "yes" } else { "NO" }
                        );
                    }
                }
            }
        }
        if o.repeat > 1 {
            for (ti, &threads) in o.threads.iter().enumerate().skip(1) {
                let mut ratios: Vec<f64> = walls[0]
                    .iter()
                    .zip(&walls[ti])
                    .map(|(a, b)| a / b)
                    .collect();
                ratios.sort_by(f64::total_cmp);
                let median = if ratios.len() % 2 == 1 {
                    ratios[ratios.len() / 2]
                } else {
                    0.5 * (ratios[ratios.len() / 2 - 1] + ratios[ratios.len() / 2])
                };
                let best = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
                println!(
                    "{name} {threads}t vs {}t over {} back-to-back repeats: speed-up median {median:.2}x, range {:.2}-{:.2}x, \
                     best-of-{} times {:.2}x; runs at or above 1.8x: {}; final states bit-identical: {}; load {}",
                    o.threads[0],
                    o.repeat,
                    ratios[0],
                    ratios[ratios.len() - 1],
                    o.repeat,
                    best(&walls[0]) / best(&walls[ti]),
                    ratios.iter().filter(|&&r| r >= 1.8).count(),
                    if identical { "yes" } else { "NO" },
                    load_average()
                );
            }
        }
    }
}

/// The per-region profile of one run (see `polydem::world::region_profile`): per section, runs, CPU time
/// and its share of the run's CPU time, and for a parallel region the imbalance (busiest thread / mean).
fn print_profile(
    label: &str,
    profile: &[(
        polydem::world::region_profile::Section,
        polydem::world::region_profile::SectionStats,
    )],
    run_cpu: Duration,
) {
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let mut serial = Duration::ZERO;
    for (section, s) in profile {
        if s.runs == 0 {
            continue;
        }
        let is_serial = section.name().starts_with("serial");
        if is_serial {
            serial += s.cpu;
        }
        println!(
            "{label} profile {:<26} runs {:>5}, cpu {:>8.1} ms ({:>5.2} % of the run's cpu), wall {:>8.1} ms{}",
            section.name(),
            s.runs,
            ms(s.cpu),
            100.0 * s.cpu.as_secs_f64() / run_cpu.as_secs_f64(),
            ms(s.wall),
            if is_serial {
                String::new()
            } else {
                format!(
                    ", imbalance (busiest / mean thread cpu) {:.3}, costliest chunk / mean {:.3}",
                    s.imbalance(),
                    s.costliest_chunk.as_secs_f64() / s.mean.as_secs_f64()
                )
            }
        );
    }
    println!(
        "{label} profile serial sections: cpu {:.1} ms = {:.2} % of the run's cpu",
        ms(serial),
        100.0 * serial.as_secs_f64() / run_cpu.as_secs_f64()
    );
}

/// The fork/join cost of one parallel region of the step on each thread count, measured through the
/// step's own helper ([`for_each_item`]) over `items` items of about `work` ns each (a chain of dependent
/// square roots), with a serial gap between regions as between the stages of a step (during it the pool's
/// threads go idle and, after a while, to sleep: waking them is part of the cost). The minimum over the
/// repeats is the cost on an idle machine, the median what this run saw. Region time on two threads minus
/// half the one-thread time is the overhead; compared with the per-item costs of the stages it gives the
/// item counts from which a region pays (see `src/world/parallel.rs`).
///
/// [`for_each_item`]: polydem::world::parallel::for_each_item
fn region_overhead(threads: &[usize]) {
    use polydem::world::parallel::for_each_item;
    const REPEATS: usize = 5000;
    println!("load {}", load_average());
    // ~4 ns per square root on this machine class: `depth` dependent roots per item.
    let item = |depth: usize, x: &mut f64| {
        let mut y = *x + 2.0;
        for _ in 0..depth {
            y = y.sqrt() + 1.0;
        }
        *x = y;
    };
    let spin = |d: Duration| {
        let t0 = Instant::now();
        while t0.elapsed() < d {
            std::hint::spin_loop();
        }
    };
    for (items, depth) in [(1_000usize, 5usize), (4_000, 5), (10_000, 5)] {
        for gap_us in [100u64, 1000] {
            let gap = Duration::from_micros(gap_us);
            let mut line = format!("{items} items x {depth} roots, gap {gap_us} us:");
            for &t in threads {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build()
                    .expect("thread pool");
                let mut data = vec![0.0f64; items];
                let mut times = Vec::with_capacity(REPEATS);
                pool.install(|| {
                    for _ in 0..REPEATS {
                        spin(gap);
                        let t0 = Instant::now();
                        for_each_item(true, &mut data, |_, x| item(depth, x));
                        times.push(t0.elapsed());
                    }
                });
                std::hint::black_box(&data);
                times.sort();
                let us = |d: Duration| d.as_secs_f64() * 1e6;
                line += &format!(
                    "  {t}t min {:.1} us, median {:.1} us;",
                    us(times[0]),
                    us(times[times.len() / 2])
                );
            }
            println!("{line}");
        }
    }
}

/// Writes every scene of `o.scenes` as `DIR/NAME.toml` (see the module docs): the bodies with their own
/// hull (vertices in the body frame), position, orientation, velocities; the box walls; the bed's linear
/// law with restitution and Coulomb spring; Δt and the skin of the built world.
fn write_scenes(dir: &std::path::Path, o: &Options) -> Result<(), String> {
    use polydem::shape::Shape;
    use std::fmt::Write as _;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for name in &o.scenes {
        let b = build(name)?;
        let w = &b.world;
        let spec = bed::BedSpec::rocks([25, 25, 16], 0, 0);
        let v = |x: &polydem::math::Vector| format!("[{:?}, {:?}, {:?}]", x.x, x.y, x.z);
        let mut t = String::new();
        let steps = o.warm_up + o.steps;
        let _ = writeln!(
            t,
            "# Perf scene '{name}', written by `cargo run --release --example perf_threads -- \
             --write-scenes DIR` from the seeded builder of tests/support/bed.rs (do not edit; regenerate).\n\
             # {} bodies; {steps} steps of the given time step. Run: RAYON_NUM_THREADS=1 polydem run THIS.toml --out OUT\n\
             [simulation]\ngravity = {}\nend_time = {:?}\noutput_interval = {:?}\ntime_step = {:?}\nskin = {:?}\n",
            w.bodies().len(),
            v(&w.gravity()),
            b.params.dt * steps as f64,
            b.params.dt * steps as f64,
            b.params.dt,
            w.broad_phase().skin()
        );
        // The projectile (a 7800 kg/m³ sphere) is its own material with the same law.
        let projectile = w.names().iter().position(|n| n == "projectile");
        let mut materials = vec![("rock", spec.density)];
        if projectile.is_some() {
            materials.push(("steel", 7800.0));
        }
        for (m, density) in &materials {
            let _ = writeln!(t, "[[material]]\nname = \"{m}\"\ndensity = {density:?}\n");
        }
        for (i, (a, _)) in materials.iter().enumerate() {
            for (b_name, _) in &materials[i..] {
                let _ = writeln!(
                    t,
                    "[[interaction]]\nmaterials = [\"{a}\", \"{b_name}\"]\nlaw = \"linear\"\nnormal_stiffness = {:?}\n\
                     restitution = {:?}\ntangential_stiffness = {:?}\nfriction = {:?}\n",
                    spec.stiffness,
                    spec.restitution,
                    0.5 * spec.stiffness,
                    spec.friction
                );
            }
        }
        for (k, shape) in w.shapes().iter().enumerate() {
            match shape {
                Shape::Polyhedron(p) => {
                    let points: Vec<String> = p.vertices().iter().map(|x| v(&x.coords)).collect();
                    let _ = writeln!(
                        t,
                        "[[shape]]\nname = \"s{k}\"\nkind = \"polyhedron\"\npoints = [{}]\n",
                        points.join(", ")
                    );
                }
                Shape::Sphere(sph) => {
                    let _ = writeln!(
                        t,
                        "[[shape]]\nname = \"s{k}\"\nkind = \"sphere\"\nradius = {:?}\n",
                        sph.radius()
                    );
                }
                Shape::Plane(_) => return Err(format!("{name}: a plane body cannot be written")),
                _ => return Err(format!("{name}: shape s{k} has no [[shape]] kind to write")),
            }
        }
        for (i, body) in w.bodies().iter().enumerate() {
            let q = body.orientation.quaternion();
            let _ = writeln!(
                t,
                "[[body]]\nname = \"{}\"\nshape = \"s{}\"\nmaterial = \"{}\"\nposition = {}\n\
                 orientation = [{:?}, {:?}, {:?}, {:?}]\nvelocity = {}\nangular_velocity = {}\n",
                w.names()[i],
                w.shape_indices()[i],
                if Some(i) == projectile {
                    "steel"
                } else {
                    "rock"
                },
                v(&body.position.coords),
                q.w,
                q.i,
                q.j,
                q.k,
                v(&body.velocity),
                v(&body.angular_velocity())
            );
        }
        for wall in w.walls() {
            let normal = wall.pose.rotation * wall.plane.normal();
            let point =
                wall.pose * polydem::math::Point::from(wall.plane.normal() * wall.plane.offset());
            let _ = writeln!(
                t,
                "[[wall]]\nname = \"{}\"\nmaterial = \"rock\"\npoint = {}\nnormal = {}\n",
                wall.name,
                v(&point.coords),
                v(&normal)
            );
        }
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, t).map_err(|e| format!("{}: {e}", path.display()))?;
        println!("wrote {} ({} bodies)", path.display(), w.bodies().len());
    }
    Ok(())
}
