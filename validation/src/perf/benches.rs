//! The fixed benchmark set: what users run, each driven through scene files and the engine's public entry
//! points so that it survives changes inside the engine.
//!
//! A benchmark does its setup, then calls [`measured`] once per figure. The instruction counter
//! ([`super::callgrind`]) counts only what runs inside [`measured`], one dump per call, so setup, file
//! reading and the harness itself never enter a figure. Every figure also reports a *work* number (contacts,
//! bodies, bytes): the same binary on the same input must do the same work, and a change of it says that a
//! figure moved because the work moved.
//!
//! States that take many steps to reach (a settled box of polyhedra) are prepared natively
//! ([`prepare`]) before the counted runs, so the slow instrumented run only does the measured part.

use std::hint::black_box;
use std::path::{Path, PathBuf};

use polydem::contact::{
    intersect_polyhedra_cached, query_polyhedra_with, ContactGeometry, ContactTolerances,
    EpaScratch, PairCache, QueryCounters,
};
use polydem::io::checkpoint;
use polydem::io::vtk::VtkWriter;
use polydem::math::Pose;
use polydem::scene::{load_scene, RunObserver, Simulation, StepPath};
use polydem::shape::ConvexPolyhedron;
use polydem::world::{step, StepScratch};
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::experiment::{run_experiment_with, BedSource};
use polydem_rockfill::penetration::PenetrationOptions;

use crate::cases::contact::random_set;
use crate::pairsets::{Intent, RandomSetSpec};

/// A benchmark of the set: its name and the figures it produces (in the order it measures them).
pub struct Bench {
    pub name: &'static str,
    /// What it measures, for the dashboard and `cargo perf list`.
    pub what: &'static str,
    run: fn(&Inputs, &mut Regions) -> Result<(), String>,
}

/// The shape classes of the contact benchmarks (those of the contact case's pair sets).
pub const CONTACT_CLASSES: [&str; 7] = [
    "tet", "box", "hull8", "hull16", "hull32", "hull64", "voronoi",
];
/// Overlapping and separated pairs per class in the contact benchmarks.
const CONTACT_PAIRS: usize = 20;
/// Seed of the contact pair sets (the wall-time peer figures use the same).
pub const CONTACT_SEED: u64 = 7321;
/// Steps of each step benchmark, after one step outside the count (the first step builds the neighbour
/// lists and the contact store, which later steps only update).
const POLYHEDRA_BOX_STEPS: usize = 10;
const SPHERE_BED_STEPS: usize = 10;
/// Steps of the sphere-bed run through [`Simulation::run_observed`] (its set-up included).
const SPHERE_BED_RUN_STEPS: u64 = 50;
/// Penetration steps from the saved bed: the projectile reaches the bed after ~100 steps.
const PENETRATION_STEPS: u64 = 150;
/// Simulated time (s) of the prepared box of polyhedra: the scene's end, when the bodies rest in a pile.
const POLYHEDRA_BOX_SETTLED: &str = "polyhedra_box_settled.pdck";

/// The benchmark set, in the order it runs.
pub fn all() -> Vec<Bench> {
    vec![
        Bench {
            name: "contact",
            what: "contact queries between two convex polyhedra, per shape class: the full GJK/EPA query on \
                   20 overlapping pairs and the boolean test on 20 separated pairs, each from a cold pair \
                   cache and again warm (the cache of a first query of the same pair); and the full query \
                   (GJK distance) on the 20 separated pairs from a cold cache",
            run: contact,
        },
        Bench {
            name: "step_polyhedra_box",
            what: "10 steps of 1000 polyhedra resting in a box of five walls (reference/polyhedra_box, \
                   prepared by running the scene to its end)",
            run: step_polyhedra_box,
        },
        Bench {
            name: "step_sphere_bed",
            what: "10 steps of sphere bed a (scenes/sphere_bed_a_hertz_5ms.toml) through the general step \
                   (the energy ledger on), and 50 steps of it with the ledger off through the run that \
                   `polydem run` uses, on the flat sphere layout, its set-up included",
            run: step_sphere_bed,
        },
        Bench {
            name: "rockfill_penetration",
            what: "the quick rockfill penetration, 150 steps from the saved bed (reference/rockfill/quick_bed) \
                   through the experiment's entry point, bed loading included",
            run: rockfill_penetration,
        },
        Bench {
            name: "io",
            what: "scene load and build (the 1000-polyhedra box and sphere bed a), one VTK frame and one \
                   checkpoint written and read back (the settled box)",
            run: io,
        },
    ]
}

/// Where a benchmark finds its inputs: the repository and the prepared states.
pub struct Inputs {
    pub root: PathBuf,
    pub prepared: PathBuf,
    /// Turn off the step's motion-bound skip in the step benchmarks: a planted regression (exact, so the
    /// physics is the same, but more pairs reach the narrow phase), to show that the gate catches one.
    pub plant_regression: bool,
}

impl Inputs {
    fn path(&self, relative: &str) -> PathBuf {
        self.root.join(relative)
    }
}

/// The figures a benchmark measured: name and work, in order.
#[derive(Default)]
pub struct Regions {
    pub figures: Vec<(String, u64)>,
}

impl Regions {
    /// Sets the work of the figure measured last (for work known only once its result is checked).
    fn set_work(&mut self, work: u64) {
        self.figures.last_mut().expect("a figure was measured").1 = work;
    }
}

/// Runs `f` as the measured region of `figure`: the instruction counter collects inside this function
/// only and dumps at its end. `work` of the result tells how much the region did.
#[inline(never)]
pub fn measured<R>(
    regions: &mut Regions,
    figure: String,
    f: impl FnOnce() -> R,
    work: impl FnOnce(&R) -> u64,
) {
    let result = black_box(measured_region(f));
    regions.figures.push((figure, work(&result)));
}

/// The function callgrind is told to collect in and dump after (see [`super::callgrind::REGION`]).
#[inline(never)]
pub fn measured_region<R>(f: impl FnOnce() -> R) -> R {
    black_box(f())
}

/// Runs the benchmark `name` and returns its figures.
pub fn run(name: &str, inputs: &Inputs) -> Result<Vec<(String, u64)>, String> {
    let bench = all()
        .into_iter()
        .find(|b| b.name == name)
        .ok_or_else(|| format!("no benchmark named `{name}` (see `cargo perf list`)"))?;
    let mut regions = Regions::default();
    (bench.run)(inputs, &mut regions)?;
    Ok(regions.figures)
}

/// Prepares the states the benchmarks start from (natively, before any counted run) in `inputs.prepared`.
pub fn prepare(inputs: &Inputs) -> Result<(), String> {
    std::fs::create_dir_all(&inputs.prepared)
        .map_err(|e| format!("{}: {e}", inputs.prepared.display()))?;
    let mut sim = scene(&inputs.path("reference/polyhedra_box/scene.toml"))?;
    sim.run(|_| Ok(()), |_, _| Ok(()))
        .map_err(|e| format!("polyhedra box: {e}"))?;
    let path = inputs.prepared.join(POLYHEDRA_BOX_SETTLED);
    checkpoint::save(&path, &sim).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(())
}

fn scene(path: &Path) -> Result<Simulation, String> {
    load_scene(path).map_err(|e| e.to_string())
}

fn settled_box(inputs: &Inputs) -> Result<Simulation, String> {
    let path = inputs.prepared.join(POLYHEDRA_BOX_SETTLED);
    checkpoint::load(&path)
        .map(|payload| payload.simulation)
        .map_err(|e| format!("{}: {e} (run `cargo perf` to prepare it)", path.display()))
}

struct ContactPair {
    a: ConvexPolyhedron,
    pos1: Pose,
    b: ConvexPolyhedron,
    pos2: Pose,
}

fn contact_pairs(class: &str) -> Result<(Vec<ContactPair>, Vec<ContactPair>), String> {
    let spec = RandomSetSpec {
        classes: vec![class.to_string()],
        sizes: vec![1.0],
        pairs_per_class_and_size: 2 * CONTACT_PAIRS,
        seed: CONTACT_SEED,
        touching_fraction: 0.0,
        separated_fraction: 0.5,
        overlap_min_rel: 1e-6,
        overlap_max_rel: 0.3,
    };
    let pairs = random_set(&spec, || {}).map_err(|e| e.to_string())?;
    let (mut overlapping, mut separated) = (Vec::new(), Vec::new());
    for pair in pairs {
        let (a, pos1) =
            ConvexPolyhedron::from_points(&pair.a).map_err(|e| format!("{}: {e}", pair.id))?;
        let (b, pos2) =
            ConvexPolyhedron::from_points(&pair.b).map_err(|e| format!("{}: {e}", pair.id))?;
        let built = ContactPair { a, pos1, b, pos2 };
        match pair.intent {
            Intent::Overlap(_) => overlapping.push(built),
            Intent::Separated(_) => separated.push(built),
            _ => {}
        }
    }
    Ok((overlapping, separated))
}

/// The full contact query run over a pair list, with the tolerances and buffers the runs share.
struct Query<'a> {
    tol: &'a ContactTolerances,
    scratch: &'a mut EpaScratch,
    counters: &'a mut QueryCounters,
}

impl<'a> Query<'a> {
    fn new(
        tol: &'a ContactTolerances,
        scratch: &'a mut EpaScratch,
        counters: &'a mut QueryCounters,
    ) -> Self {
        Self {
            tol,
            scratch,
            counters,
        }
    }

    /// Queries every pair with its cache; returns how many answers `hit` accepts (the work the figure
    /// reports, which also keeps the queries from being optimised away).
    fn count(
        &mut self,
        pairs: &[ContactPair],
        caches: &mut [PairCache],
        hit: impl Fn(&ContactGeometry) -> bool,
    ) -> u64 {
        let mut hits = 0u64;
        for (p, cache) in pairs.iter().zip(caches) {
            let g = query_polyhedra_with(
                &p.pos1,
                &p.a,
                &p.pos2,
                &p.b,
                self.tol,
                cache,
                self.scratch,
                self.counters,
            );
            hits += u64::from(hit(&g));
        }
        hits
    }
}

fn contact(_: &Inputs, regions: &mut Regions) -> Result<(), String> {
    let tol = ContactTolerances::default();
    let mut scratch = EpaScratch::new(&tol);
    let mut counters = QueryCounters::default();
    for class in CONTACT_CLASSES {
        let (overlapping, separated) = contact_pairs(class)?;
        let mut caches = vec![PairCache::default(); overlapping.len()];
        let mut query_all = |caches: &mut [PairCache]| {
            let mut query = Query::new(&tol, &mut scratch, &mut counters);
            query.count(&overlapping, caches, |g| g.depth > 0.0)
        };
        measured(
            regions,
            format!("contact_overlap_cold/{class}"),
            || query_all(&mut caches),
            |&n| n,
        );
        measured(
            regions,
            format!("contact_overlap_warm/{class}"),
            || query_all(&mut caches),
            |&n| n,
        );
        let mut caches = vec![PairCache::default(); separated.len()];
        let mut test_all = |caches: &mut [PairCache]| {
            let mut hits = 0u64;
            for (p, cache) in separated.iter().zip(caches) {
                hits += u64::from(intersect_polyhedra_cached(
                    &p.pos1,
                    &p.a,
                    &p.pos2,
                    &p.b,
                    cache,
                    &mut counters,
                ));
            }
            hits
        };
        measured(
            regions,
            format!("contact_separated_cold/{class}"),
            || test_all(&mut caches),
            |&n| n,
        );
        measured(
            regions,
            format!("contact_separated_warm/{class}"),
            || test_all(&mut caches),
            |&n| n,
        );
        let mut caches = vec![PairCache::default(); separated.len()];
        measured(
            regions,
            format!("contact_distance_cold/{class}"),
            || {
                let mut query = Query::new(&tol, &mut scratch, &mut counters);
                query.count(&separated, &mut caches, |g| g.distance > 0.0)
            },
            |&n| n,
        );
    }
    Ok(())
}

/// Runs `steps` steps of `sim` as the figure `figure`, after one uncounted step. Work: contacts at the end.
fn steps(
    inputs: &Inputs,
    regions: &mut Regions,
    figure: &str,
    sim: &mut Simulation,
    steps: usize,
) -> Result<(), String> {
    if inputs.plant_regression {
        sim.params.skips.motion_bound = false;
    }
    let mut scratch = StepScratch::default();
    step(&sim.params, &mut sim.world, &mut scratch).map_err(|e| e.to_string())?;
    let mut failure = None;
    measured(
        regions,
        figure.to_string(),
        || {
            for _ in 0..steps {
                if let Err(e) = step(&sim.params, &mut sim.world, &mut scratch) {
                    failure = Some(e.to_string());
                    break;
                }
            }
        },
        |_| 0,
    );
    if let Some(e) = failure {
        return Err(format!("{figure}: {e}"));
    }
    regions.set_work(loaded_contacts(sim));
    Ok(())
}

/// Contacts that carry a force: the work of the step figures.
fn loaded_contacts(sim: &Simulation) -> u64 {
    let states = sim.world.contacts().states();
    states.iter().filter(|s| s.force_on_b.norm() > 0.0).count() as u64
}

fn step_polyhedra_box(inputs: &Inputs, regions: &mut Regions) -> Result<(), String> {
    let mut sim = settled_box(inputs)?;
    steps(
        inputs,
        regions,
        "step/polyhedra_box",
        &mut sim,
        POLYHEDRA_BOX_STEPS,
    )
}

fn step_sphere_bed(inputs: &Inputs, regions: &mut Regions) -> Result<(), String> {
    let path = inputs.path("scenes/sphere_bed_a_hertz_5ms.toml");
    let mut sim = scene(&path)?;
    steps(
        inputs,
        regions,
        "step/sphere_bed_a",
        &mut sim,
        SPHERE_BED_STEPS,
    )?;
    // The same bed as `polydem run` runs it with the energy ledger off: the pipeline takes the flat sphere
    // layout; its set-up (copy into the layout, first neighbour lists) is part of the figure.
    let mut sim = scene(&path)?;
    sim.params.energy_ledger = false;
    sim.steps = SPHERE_BED_RUN_STEPS;
    let mut result = None;
    measured(
        regions,
        "run/sphere_bed_a_no_ledger".to_string(),
        || result = Some(sim.run_observed(&mut AtTheEnd)),
        |_| 0,
    );
    let summary = result.expect("measured").map_err(|e| e.to_string())?;
    if summary.path != StepPath::FlatSpheres {
        return Err("sphere bed a without the ledger did not take the flat sphere layout".into());
    }
    regions.set_work(loaded_contacts(&sim));
    Ok(())
}

/// An observer that reads the state at the start and the end of a run only.
struct AtTheEnd;

impl RunObserver for AtTheEnd {
    fn wants_state(&self, _: u64) -> bool {
        false
    }
    fn observe(&mut self, _: &Simulation, _: u64) -> std::io::Result<()> {
        Ok(())
    }
}

fn rockfill_penetration(inputs: &Inputs, regions: &mut Regions) -> Result<(), String> {
    let config_path = inputs.path("scenes/rockfill/quick.toml");
    let config = ExperimentConfig::load(&config_path).map_err(|e| e.to_string())?;
    let bed = inputs.path("reference/rockfill/quick_bed");
    let options = PenetrationOptions {
        max_steps: Some(PENETRATION_STEPS),
        ..PenetrationOptions::default()
    };
    let mut result = None;
    measured(
        regions,
        "rockfill/penetration_quick".to_string(),
        || {
            result = Some(run_experiment_with(
                &config,
                BedSource::Load(&bed),
                &options,
                &mut |_, _| {},
            ));
        },
        |_| 0,
    );
    let result = result.expect("measured").map_err(|e| e.to_string())?;
    let last = result.penetration.rows.last().map_or(0, |row| row.contacts);
    regions.set_work(last as u64);
    Ok(())
}

fn io(inputs: &Inputs, regions: &mut Regions) -> Result<(), String> {
    for (figure, relative) in [
        (
            "scene_load/polyhedra_box",
            "reference/polyhedra_box/scene.toml",
        ),
        (
            "scene_load/sphere_bed_a",
            "scenes/sphere_bed_a_hertz_5ms.toml",
        ),
    ] {
        let path = inputs.path(relative);
        let mut loaded = None;
        measured(
            regions,
            figure.to_string(),
            || loaded = Some(load_scene(&path)),
            |_| 0,
        );
        let sim = loaded
            .expect("measured")
            .map_err(|e| format!("{relative}: {e}"))?;
        regions.set_work(sim.world.bodies().len() as u64);
    }
    let sim = settled_box(inputs)?;
    let out = inputs.prepared.join("io");
    let mut writer = VtkWriter::new(&out, &sim.world, polydem::io::vtk::VtkEncoding::default())
        .map_err(|e| format!("{}: {e}", out.display()))?;
    measured(
        regions,
        "vtk_frame/polyhedra_box".to_string(),
        || writer.write_frame(&sim.world),
        |_| 0,
    );
    regions.set_work(writer.bytes_written);
    let path = out.join("box.pdck");
    let mut saved = None;
    measured(
        regions,
        "checkpoint_write/polyhedra_box".to_string(),
        || saved = Some(checkpoint::save(&path, &sim)),
        |_| 0,
    );
    let bytes = saved
        .expect("measured")
        .map_err(|e| format!("{}: {e}", path.display()))?;
    regions.set_work(bytes);
    let mut read = None;
    measured(
        regions,
        "checkpoint_read/polyhedra_box".to_string(),
        || read = Some(checkpoint::load(&path)),
        |_| 0,
    );
    let payload = read
        .expect("measured")
        .map_err(|e| format!("{}: {e}", path.display()))?;
    regions.figures.last_mut().expect("just measured").1 =
        payload.simulation.world.bodies().len() as u64;
    Ok(())
}
