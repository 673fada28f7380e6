//! The flat sphere path books the energy ledger to the same bits as the general step.
//!
//! With `energy_ledger` on (the scenes' default), the general step books per contact and step the
//! damping work of the last and the new damping force, the Coulomb slip work and the tangential
//! stiffness work, and sums them in candidate order (`src/world/energy.rs`); the flat path keeps each
//! listed pair's last damping force and contact point, books the same terms with the same functions and
//! sums them in pair order (`src/world/sphere_flat/ledger.rs`). The sphere beds (Hertz–Mindlin with the
//! tangential dashpot, and the linear spring–dashpot) have new, persistent and opening contacts between
//! spheres and against the walls once the ball lands (step ~50), and the flat lists are rebuilt, so every
//! branch of the booking runs. Compared bit for bit: every ledger term, the last step's terms in the
//! loads, and the bodies.

#[path = "support/world_bits.rs"]
#[allow(dead_code)]
mod world_bits;

use std::ops::ControlFlow;
use std::path::Path;

use polydem::scene::{load_scene, RunObserver, Simulation, StepPath};
use polydem::world::{step, SphereSim, StepScratch, World};

const STEPS: u64 = 300;

const SCENES: [&str; 3] = [
    "scenes/sphere_bed_a_hertz_5ms.toml",
    "scenes/sphere_bed_b_hertz_200ms.toml",
    "scenes/sphere_bed_c_linear_5ms.toml",
];

fn scene(file: &str) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let sim = load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        sim.params.energy_ledger,
        "{file}: the energy ledger must be on by default"
    );
    sim
}

fn general(params: &polydem::world::StepParams, world: &World, steps: u64) -> World {
    let mut world = world.clone();
    let mut scratch = StepScratch::default();
    for _ in 0..steps {
        step(params, &mut world, &mut scratch).unwrap_or_else(|e| panic!("general step: {e}"));
    }
    world
}

/// `steps` flat steps from `world` (as a run of steps, which on several threads runs them as jobs of
/// the team), written back into a copy of it.
fn flat(params: &polydem::world::StepParams, world: &World, steps: u64, threads: usize) -> World {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        let mut flat = SphereSim::from_world(world, params)
            .unwrap_or_else(|e| panic!("the sphere bed must take the flat path: {e}"));
        let done = flat
            .run_steps(steps, |_, _| ControlFlow::Continue(()))
            .unwrap_or_else(|e| panic!("flat steps: {e}"));
        assert_eq!(done, steps, "flat steps run");
        let mut out = world.clone();
        flat.write_back(&mut out);
        out
    })
}

/// The ledger's terms and the last step's contact terms, named.
fn ledger_values(w: &World) -> [(&'static str, f64); 9] {
    let l = &w.ledger();
    [
        ("initial_total", l.initial_total().unwrap_or(f64::NAN)),
        ("dissipated_damping", l.dissipated_damping()),
        ("dissipated_friction", l.dissipated_friction()),
        ("dissipated_viscous", l.dissipated_viscous()),
        ("external_work", l.external_work()),
        ("tangential_stiffness_work", l.tangential_stiffness_work()),
        ("loads.damping_work", w.loads().damping_work()),
        (
            "loads.friction_dissipation",
            w.loads().friction_dissipation(),
        ),
        (
            "loads.tangential_stiffness_work",
            w.loads().tangential_stiffness_work(),
        ),
    ]
}

/// The first difference in bits between the ledgers and bodies of two worlds, if any.
fn difference(general: &World, flat: &World) -> Option<String> {
    if let Some(d) = world_bits::body_difference(general, flat) {
        return Some(d);
    }
    for ((name, g), (_, f)) in ledger_values(general).into_iter().zip(ledger_values(flat)) {
        if g.to_bits() != f.to_bits() {
            return Some(format!("{name}: flat {f:e} against general {g:e} (bits)"));
        }
    }
    None
}

/// The run booked damping and friction work, and stiffness work where the tangential stiffness follows
/// the overlap (Hertz–Mindlin; zero for the linear spring's constant k_t), so that the comparison can
/// fail.
fn assert_booked(file: &str, w: &World) {
    let l = &w.ledger();
    let mindlin = !file.contains("linear");
    assert!(
        l.dissipated_damping() > 0.0
            && l.dissipated_friction() > 0.0
            && (l.tangential_stiffness_work() != 0.0) == mindlin,
        "{file}: damping {:e} J, friction {:e} J, stiffness work {:e} J booked: expected > 0, > 0, \
         nonzero for a Hertz–Mindlin scene only",
        l.dissipated_damping(),
        l.dissipated_friction(),
        l.tangential_stiffness_work()
    );
}

#[test]
fn flat_ledger_is_the_general_ledger_bit_for_bit_on_one_and_two_threads() {
    for file in SCENES {
        let sim = scene(file);
        let reference = general(&sim.params, &sim.world, STEPS);
        assert_booked(file, &reference);
        for threads in [1, 2] {
            let written = flat(&sim.params, &sim.world, STEPS, threads);
            if let Some(d) = difference(&reference, &written) {
                panic!("{file}, {STEPS} steps, {threads} thread(s), flat against general: {d}");
            }
        }
    }
}

/// A flat run from a world the general step left with contacts in progress takes their last forces
/// from the contact store (the import of the first build): the ledger continues with the same bits.
#[test]
fn flat_ledger_continues_a_general_run() {
    const FIRST: u64 = 120;
    for file in [SCENES[0], SCENES[2]] {
        let sim = scene(file);
        let midway = general(&sim.params, &sim.world, FIRST);
        let reference = general(&sim.params, &midway, STEPS - FIRST);
        for threads in [1, 2] {
            let written = flat(&sim.params, &midway, STEPS - FIRST, threads);
            if let Some(d) = difference(&reference, &written) {
                panic!(
                    "{file}, {FIRST} general then {} flat steps on {threads} thread(s), against {STEPS} \
                     general steps: {d}",
                    STEPS - FIRST
                );
            }
        }
    }
}

/// Reads the state every `every` steps.
struct Every(u64);

impl RunObserver for Every {
    fn wants_state(&self, step: u64) -> bool {
        step.is_multiple_of(self.0)
    }
    fn observe(&mut self, _: &Simulation, _: u64) -> std::io::Result<()> {
        Ok(())
    }
}

/// With the ledger on, the pipeline takes the flat layout for a world of free spheres, and the ledger
/// the observer reads is the general step's.
#[test]
fn run_observed_takes_the_flat_layout_with_the_ledger_on() {
    let file = SCENES[0];
    let mut sim = scene(file);
    sim.steps = STEPS;
    let reference = general(&sim.params, &sim.world, STEPS);
    let summary = sim
        .run_observed(&mut Every(100))
        .unwrap_or_else(|e| panic!("{file}: run_observed: {e}"));
    assert_eq!(
        summary.path,
        StepPath::FlatSpheres,
        "{file}, ledger on, run_observed: the pipeline must take the flat sphere layout"
    );
    assert_eq!(summary.steps, STEPS, "{file}: steps run");
    if let Some(d) = difference(&reference, &sim.world) {
        panic!("{file}, {STEPS} steps, run_observed against the general step: {d}");
    }
}
