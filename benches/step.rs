//! Macro benchmarks of the world step: throughput in particle-steps per second (criterion's "elements")
//! on fixed, seeded scenes, with 1 and 2 threads, and each skip of the step on and off on a scene where it
//! matters.
//!
//! Scenes (built in code by `tests/support/bed.rs`, seeded; see there for the lattice and the law):
//! - `poly_bed`: 10^4 polyhedra (6 distinct random 14-point hulls) in a box, dropped from a tight lattice
//!   with random velocities; measured while it collapses and settles under gravity (after a warm-up that
//!   brings it into contact);
//! - `poly_bed_projectile`: the same bed struck by a 0.25 m steel sphere at 10 m/s;
//! - `sphere_bed`: 10^4 spheres, same box and law;
//! - group `skips`: each skip on and off (1 thread) on a scene of 2000 bodies where it matters;
//! - group `sleeping`: a settled 4-layer bed of 1600 spheres struck by a steel sphere, sleeping on and off;
//! - group `threshold`: small beds (16–1000 bodies) with the stages forced serial or parallel on 2 threads,
//!   the measurement behind `polydem::world::parallel::DEFAULT_MIN_CANDIDATES`.
//!
//! Each step-group prints the mean number of contacts per step to stderr, so that contacts per second can be
//! derived from the throughput. Run with `cargo bench --bench step [-- FILTER]`.

#[path = "../tests/support/bed.rs"]
mod bed;

use std::cell::OnceCell;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use polydem::dynamics::{Motion, ViscousDamping};
use polydem::law::{ContactModel, DampingLaw, TangentialLaw};
use polydem::math::Vector;
use polydem::world::{
    step, Parallelism, Skips, SleepParams, StepCounters, StepParams, StepScratch, World,
};

/// Steps run before measuring, so that the bodies of the lattice have started to collide.
const WARM_UP_STEPS: usize = 100;

/// Steps measured from one copy of the warm scene before it is reset to the warm state: every thread count
/// and every setting measures the same stretch of the dynamics.
const WINDOW: u64 = 40;

struct Scene {
    world: World,
    params: StepParams,
}

/// A scene built on first use, so that benchmarks left out by a filter cost no setup.
struct Lazy {
    name: &'static str,
    /// Bodies in the scene (for the throughput in particle-steps).
    bodies: u64,
    build: Box<dyn Fn() -> Scene>,
    cell: OnceCell<Scene>,
}

impl Lazy {
    fn new(name: &'static str, bodies: usize, build: impl Fn() -> Scene + 'static) -> Self {
        Self {
            name,
            bodies: bodies as u64,
            build: Box::new(build),
            cell: OnceCell::new(),
        }
    }

    fn get(&self) -> &Scene {
        self.cell.get_or_init(|| (self.build)())
    }
}

/// A bed of `spec` (with `edit` applied to the built bed), warmed up.
fn bed_scene(spec: bed::BedSpec, edit: impl Fn(&mut bed::Bed)) -> Scene {
    let mut b = bed::build(&spec);
    edit(&mut b);
    let mut scene = Scene {
        world: b.world,
        params: b.params,
    };
    let mut scratch = StepScratch::default();
    for _ in 0..WARM_UP_STEPS {
        step(&scene.params, &mut scene.world, &mut scratch).expect("warm-up step");
    }
    scene
}

fn lattice(cells: [usize; 3], sphere_every: usize, seed: u64) -> bed::BedSpec {
    bed::BedSpec {
        gap: 0.0,
        speed: 1.0,
        ..bed::BedSpec::rocks(cells, sphere_every, seed)
    }
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

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

/// Benchmarks `scene` with its parameters edited by `edit` under `label` in `group` for each of
/// `threads`; prints the contacts per step and the stage counters to stderr.
fn bench_threads(
    c: &mut Criterion,
    group: &str,
    scene: &Lazy,
    edit: impl Fn(&mut StepParams),
    label: &str,
    threads: &[usize],
) {
    let mut g = c.benchmark_group(group);
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(6))
        .throughput(Throughput::Elements(scene.bodies));
    for &n in threads {
        let pool = pool(n);
        let mut counters = StepCounters::default();
        g.bench_function(BenchmarkId::new(label, format!("{n}t")), |b| {
            let s = scene.get();
            let mut params = s.params;
            edit(&mut params);
            b.iter_custom(|iters| run_windows(s, &params, &pool, iters, &mut counters))
        });
        if counters.steps == 0 {
            continue;
        }
        let steps = counters.steps as f64;
        eprintln!(
            "{group}/{label}/{n}t [{}]: {:.0} contacts per step, {:.0} pairs tested per step over {} steps; {counters}",
            scene.name,
            counters.contacts as f64 / steps,
            (counters.body_pairs_tested + counters.wall_pairs_tested) as f64 / steps,
            counters.steps,
        );
    }
    g.finish();
}

fn scenes(c: &mut Criterion) {
    let poly = Lazy::new("poly_bed", 10_000, || {
        bed_scene(lattice([25, 25, 16], 0, 1), |_| {})
    });
    bench_threads(c, "step", &poly, |_| {}, "poly_bed", &[1, 2]);
    let struck = Lazy::new("poly_bed_projectile", 10_001, || {
        bed_scene(lattice([25, 25, 16], 0, 1), |b| {
            // Starts 1 cm above the lattice: it strikes during the warm-up and ploughs on through the
            // measured steps.
            bed::add_projectile(b, 0.125, 7800.0, 0.01, 10.0);
        })
    });
    bench_threads(c, "step", &struck, |_| {}, "poly_bed_projectile", &[1, 2]);
    let spheres = Lazy::new("sphere_bed", 10_000, || {
        bed_scene(lattice([25, 25, 16], 1, 1), |_| {})
    });
    bench_threads(c, "step", &spheres, |_| {}, "sphere_bed", &[1, 2]);
}

/// `scene` with every skip on, and with `off` applied, 1 thread.
fn skip_pair(c: &mut Criterion, scene: &Lazy, name: &str, off: fn(&mut Skips)) {
    bench_threads(
        c,
        "skips",
        scene,
        |p| p.skips = Skips::all(true),
        &format!("{name}_on"),
        &[1],
    );
    bench_threads(
        c,
        "skips",
        scene,
        |p| {
            p.skips = Skips::all(true);
            off(&mut p.skips);
        },
        &format!("{name}_off"),
        &[1],
    );
}

/// Each skip on and off (1 thread) on a scene of 2000 bodies where it matters.
fn skips(c: &mut Criterion) {
    // Query skips and the Verlet skin: a polyhedral bed (most candidates are separated pairs).
    let poly = Lazy::new("poly_bed_2000", 2000, || {
        bed_scene(lattice([10, 10, 20], 0, 2), |_| {})
    });
    skip_pair(c, &poly, "bounding_spheres", |s| s.bounding_spheres = false);
    skip_pair(c, &poly, "cached_axis", |s| s.cached_axis = false);
    skip_pair(c, &poly, "motion_bound", |s| s.motion_bound = false);
    skip_pair(c, &poly, "warm_overlap", |s| s.warm_overlap = false);
    skip_pair(c, &poly, "verlet_skin", |s| s.verlet_skin = false);
    // μ = 0 (a spring with zero friction) and a zero damping coefficient: sphere beds.
    let frictionless = Lazy::new("sphere_bed_2000_mu0", 2000, || {
        let spec = lattice([10, 10, 20], 1, 2);
        bed_scene(spec, move |b| {
            let model = ContactModel {
                tangential: TangentialLaw::spring(0.5 * spec.stiffness, 0.0).expect("spring"),
                ..bed::model_of(&spec)
            };
            let mut laws = b.world.materials().clone();
            laws.set_model(0, 0, model);
            b.world.set_materials(laws).expect("the same materials");
        })
    });
    skip_pair(c, &frictionless, "frictionless_history", |s| {
        s.frictionless_history = false
    });
    let undamped = Lazy::new("sphere_bed_2000_e1", 2000, || {
        let spec = lattice([10, 10, 20], 1, 2);
        bed_scene(spec, move |b| {
            let model = ContactModel {
                damping: DampingLaw::Viscous { coefficient: 0.0 },
                ..bed::model_of(&spec)
            };
            let mut laws = b.world.materials().clone();
            laws.set_model(0, 0, model);
            b.world.set_materials(laws).expect("the same materials");
        })
    });
    skip_pair(c, &undamped, "undamped_contacts", |s| {
        s.undamped_contacts = false
    });
    // Zero angular momentum: a layer of 2000 frictionless spheres resting on the floor, apart.
    let layer = Lazy::new("sphere_layer_2000", 2000, || {
        let spec = bed::BedSpec {
            friction: 0.0,
            speed: 0.0,
            gap: 0.5,
            ..bed::BedSpec::rocks([50, 40, 1], 1, 2)
        };
        bed_scene(spec, |b| {
            for i in 0..b.world.body_count() {
                let r = b.world.radii()[i];
                b.world
                    .edit_body(i, |body| {
                        body.angular_momentum = Vector::zeros();
                        body.position.z = r + 1e-4;
                    })
                    .expect("a body");
            }
        })
    });
    skip_pair(c, &layer, "still_rotation", |s| {
        s.still_rotation = false;
        s.isotropic_rotation = false;
    });
    // Spinning spheres with friction: the isotropic rotation (one turn about L instead of the splitting).
    let spinning = Lazy::new("sphere_bed_2000_spinning", 2000, || {
        bed_scene(lattice([10, 10, 20], 1, 2), |_| {})
    });
    skip_pair(c, &spinning, "isotropic_rotation", |s| {
        s.isotropic_rotation = false
    });
    // Fixed bodies: a polyhedral bed whose lower half is fixed.
    let half_fixed = Lazy::new("poly_bed_2000_half_fixed", 2000, || {
        bed_scene(lattice([10, 10, 20], 0, 2), |b| {
            for i in 0..1000.min(b.world.body_count()) {
                b.world
                    .edit_body(i, |body| {
                        body.motion = Motion::Fixed;
                        body.velocity = Vector::zeros();
                        body.angular_momentum = Vector::zeros();
                    })
                    .expect("a body");
            }
        })
    });
    skip_pair(c, &half_fixed, "non_dynamic_pairs", |s| {
        s.non_dynamic_pairs = false
    });
}

/// Sleeping on and off: a settled 4-layer bed of 1600 spheres struck by a steel sphere.
fn sleeping(c: &mut Criterion) {
    let struck = Lazy::new("struck_sphere_bed_1600", 1601, || {
        let spec = bed::BedSpec {
            gap: 0.0,
            speed: 0.0,
            ..bed::BedSpec::rocks([20, 20, 4], 1, 5)
        };
        let mut b = bed::build(&spec);
        b.params.damping = ViscousDamping::MassProportional(10.0);
        let mut scratch = StepScratch::default();
        for _ in 0..3000 {
            step(&b.params, &mut b.world, &mut scratch).expect("settling");
        }
        b.params.damping = ViscousDamping::None;
        // The projectile arrives after ~310 steps, when the bed has fallen asleep (200 calm steps).
        let height = 310.0 * b.params.dt * 5.0;
        bed::add_projectile(&mut b, 0.1, 7800.0, height, 5.0);
        b.params.sleeping = SleepParams::on();
        for _ in 0..300 {
            step(&b.params, &mut b.world, &mut scratch).expect("falling asleep");
        }
        eprintln!(
            "sleeping bench: {} of {} bodies asleep before the impact",
            b.world.sleep().asleep_count(),
            b.world.bodies().len()
        );
        Scene {
            world: b.world,
            params: b.params,
        }
    });
    bench_threads(c, "sleeping", &struck, |_| {}, "sleeping_on", &[1, 2]);
    bench_threads(
        c,
        "sleeping",
        &struck,
        |p| p.sleeping = SleepParams::default(),
        "sleeping_off",
        &[1, 2],
    );
}

/// Serial against parallel stages on small scenes, 2 threads: where the parallel thresholds come from.
fn small_scene_threshold(c: &mut Criterion) {
    for (name, cells) in [
        ("bed_16", [2, 2, 4]),
        ("bed_64", [4, 4, 4]),
        ("bed_216", [6, 6, 6]),
        ("bed_1000", [10, 10, 10]),
        ("bed_4000", [20, 20, 10]),
    ] {
        let scene = Lazy::new(name, cells.iter().product(), move || {
            bed_scene(lattice(cells, 4, 3), |_| {})
        });
        bench_threads(
            c,
            "threshold",
            &scene,
            |p| {
                p.parallel = Parallelism {
                    min_candidates: usize::MAX,
                    min_bodies: usize::MAX,
                }
            },
            &format!("{name}_serial"),
            &[2],
        );
        bench_threads(
            c,
            "threshold",
            &scene,
            |p| {
                p.parallel = Parallelism {
                    min_candidates: 0,
                    min_bodies: 0,
                }
            },
            &format!("{name}_parallel"),
            &[2],
        );
    }
}

criterion_group!(benches, scenes, skips, sleeping, small_scene_threshold);
criterion_main!(benches);
