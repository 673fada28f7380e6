//! Macro benchmarks of the world step: throughput in particle-steps per second (criterion's "elements")
//! on fixed, seeded scenes, with 1 and 2 threads, and each skip of the step on and off on a scene where it
//! matters.
//!
//! Scenes (built in code by `tests/support/bed.rs`, seeded; see there for the lattice and the law):
//! - `poly_bed`: 10^4 polyhedra (6 distinct random 14-point hulls) in a box, dropped from a tight lattice
//!   with random velocities; measured while it collapses and settles under gravity (after a warm-up that
//!   brings it into contact);
//! - `poly_bed_projectile`: the same bed struck by a 0.25 m steel sphere at 20 m/s;
//! - `sphere_bed`: 10^4 spheres, same box and law.
//!
//! Each step-group prints the mean number of contacts per step to stderr, so that contacts per second can be
//! derived from the throughput. Run with `cargo bench --bench step [-- FILTER]`.

#[path = "../tests/support/bed.rs"]
mod bed;

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use polydem::world::{step, StepCounters, StepParams, StepScratch, World};

/// Steps run before measuring, so that the bodies of the lattice have started to collide.
const WARM_UP_STEPS: usize = 100;

struct Scene {
    name: &'static str,
    world: World,
    params: StepParams,
}

fn poly_bed() -> Scene {
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 1.0,
        ..bed::BedSpec::rocks([25, 25, 16], 0, 1)
    };
    let b = bed::build(&spec);
    Scene {
        name: "poly_bed",
        world: b.world,
        params: b.params,
    }
}

fn poly_bed_projectile() -> Scene {
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 1.0,
        ..bed::BedSpec::rocks([25, 25, 16], 0, 1)
    };
    let mut b = bed::build(&spec);
    // Starts 1 cm above the lattice: it strikes during the warm-up and ploughs through the measured steps.
    bed::add_projectile(&mut b, 0.125, 7800.0, 0.01, 20.0);
    Scene {
        name: "poly_bed_projectile",
        world: b.world,
        params: b.params,
    }
}

fn sphere_bed() -> Scene {
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 1.0,
        ..bed::BedSpec::rocks([25, 25, 16], 1, 1)
    };
    let b = bed::build(&spec);
    Scene {
        name: "sphere_bed",
        world: b.world,
        params: b.params,
    }
}

fn warm(mut scene: Scene) -> Scene {
    let mut scratch = StepScratch::default();
    for _ in 0..WARM_UP_STEPS {
        step(&scene.params, &mut scene.world, &mut scratch).expect("warm-up step");
    }
    scene
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// Steps measured from one copy of the warm scene before it is reset to the warm state: every thread count
/// and every setting measures the same stretch of the dynamics.
const WINDOW: u64 = 40;

/// Runs `iters` steps of `scene` in windows of [`WINDOW`] steps from its warm state, on `pool`; returns the
/// time spent in `step` and adds the step counters to `counters`.
fn run_windows(
    scene: &Scene,
    params: &StepParams,
    pool: &rayon::ThreadPool,
    iters: u64,
    counters: &mut StepCounters,
) -> Duration {
    let mut total = Duration::ZERO;
    let mut done = 0;
    let mut scratch = StepScratch::default();
    while done < iters {
        let mut world = scene.world.clone();
        let n = WINDOW.min(iters - done);
        let t = Instant::now();
        pool.install(|| {
            for _ in 0..n {
                let r = step(params, &mut world, &mut scratch).expect("step");
                counters.merge(&r.counters);
            }
        });
        total += t.elapsed();
        done += n;
    }
    total
}

/// Benchmarks `scene` with `params` under `label` in `group` for each of `threads`; prints the contacts per
/// step and the stage times to stderr.
fn bench_threads(
    c: &mut Criterion,
    group: &str,
    scene: &Scene,
    params: &StepParams,
    label: &str,
    threads: &[usize],
) {
    let mut g = c.benchmark_group(group);
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8))
        .throughput(Throughput::Elements(scene.world.bodies.len() as u64));
    for &n in threads {
        let pool = pool(n);
        let mut counters = StepCounters::default();
        g.bench_function(BenchmarkId::new(label, format!("{n}t")), |b| {
            b.iter_custom(|iters| run_windows(scene, params, &pool, iters, &mut counters))
        });
        let steps = counters.steps.max(1) as f64;
        eprintln!(
            "{group}/{label}/{n}t: {:.0} contacts per step, {:.0} pairs tested per step over {} steps; {counters}",
            counters.contacts as f64 / steps,
            (counters.body_pairs_tested + counters.wall_pairs_tested) as f64 / steps,
            counters.steps,
        );
    }
    g.finish();
}

fn scenes(c: &mut Criterion) {
    for scene in [poly_bed(), poly_bed_projectile(), sphere_bed()] {
        let scene = warm(scene);
        bench_threads(c, "step", &scene, &scene.params, scene.name, &[1, 2]);
    }
}

criterion_group!(benches, scenes);
criterion_main!(benches);
