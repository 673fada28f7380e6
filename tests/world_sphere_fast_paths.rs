//! The work a sphere run can leave out changes nothing else, bit for bit.
//!
//! The scene is the sphere-bed penetration (`scenes/sphere_bed_a_hertz_5ms.toml`: 3000 settled
//! spheres, Hertz–Mindlin with the tangential dashpot, friction and the force limit, an open box of five
//! walls, a steel ball striking at 5 m/s), run for its first 300 steps: the ball lands at step ~50, so the
//! run has new, persistent and opening contacts between spheres and against the walls.
//! - `energy_ledger = false` skips the per-contact booking of the ledger (`src/world/energy.rs`): the
//!   bodies, the loads and the contact store must be the same bits as with the ledger, and only the
//!   booked columns differ (zero without it).
//! - the `sphere_kernel` skip (`src/world/sphere_kernel.rs`) takes sphere–sphere and wall–sphere pairs
//!   past the general dispatch: bodies, loads, contact store and ledger must be the same bits with it on
//!   and off, on the Hertz–Mindlin and the linear spring–dashpot beds, and on a mixed bed of spheres and
//!   polyhedra (where it must leave the other pairs to the general path). The same skip lets a world of
//!   free spheres take the integration of `src/world/sphere_step.rs`: the comparison on the beds covers it
//!   (it applies there with the skip on and not with it off), and it must give the same bits on one and
//!   two threads with every stage forced onto the pool.

#[path = "support/bed.rs"]
mod bed;
#[path = "support/world_bits.rs"]
mod world_bits;

use std::path::Path;

use polydem::scene::{load_scene, parse_scene, Simulation};
use polydem::world::{
    sphere_step_applies, step, Parallelism, Skips, StepParams, StepScratch, World,
};

const SCENE: &str = "scenes/sphere_bed_a_hertz_5ms.toml";
const STEPS: u64 = 300;

fn scene_at(file: &str) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn scene() -> Simulation {
    scene_at(SCENE)
}

fn run(sim: Simulation, steps: u64) -> World {
    run_world(sim.params, sim.world, steps)
}

fn run_world(params: StepParams, mut world: World, steps: u64) -> World {
    let mut scratch = StepScratch::default();
    for _ in 0..steps {
        step(&params, &mut world, &mut scratch).unwrap_or_else(|e| panic!("step failed: {e}"));
    }
    world
}

/// The ledger's terms, as bits.
fn ledger_bits(w: &World) -> Vec<u64> {
    let l = &w.ledger();
    [
        l.dissipated_damping(),
        l.dissipated_friction(),
        l.dissipated_viscous(),
        l.external_work(),
        l.tangential_stiffness_work(),
        l.initial_total().unwrap_or(f64::NAN),
    ]
    .iter()
    .map(|x| x.to_bits())
    .collect()
}

/// The first difference in bits between the bodies, loads and contact stores of two worlds, if any.
fn first_difference(a: &World, b: &World) -> Option<String> {
    if let Some(d) = world_bits::body_difference(a, b) {
        return Some(d);
    }
    let (la, lb) = (
        world_bits::load_values(a, &[]),
        world_bits::load_values(b, &[]),
    );
    if let Some((k, x, y)) = world_bits::first_value_difference(&la, &lb) {
        return Some(format!("loads differ at value {k}: {x} against {y}"));
    }
    if a.contacts() != b.contacts() {
        return Some("contact stores differ".into());
    }
    None
}

#[test]
fn the_ledger_switch_changes_only_the_ledger() {
    let on = scene();
    assert!(
        on.params.energy_ledger,
        "{SCENE}: the ledger must be on by default"
    );
    let mut off = scene();
    off.params.energy_ledger = false;
    let (with, without) = (run(on, STEPS), run(off, STEPS));
    if let Some(d) = first_difference(&with, &without) {
        panic!("{SCENE}, {STEPS} steps, ledger on against off: {d}");
    }
    let (l_on, l_off) = (with.ledger(), without.ledger());
    // With the ledger the dissipation of this run is booked (so the comparison below can fail) ...
    assert!(
        l_on.dissipated_damping() > 0.0 && l_on.dissipated_friction() > 0.0,
        "{SCENE}: with the ledger, damping {} J and friction {} J booked over {STEPS} steps (expected > 0)",
        l_on.dissipated_damping(),
        l_on.dissipated_friction()
    );
    // ... and without it nothing per contact is, while the terms of the step itself are the same.
    assert_eq!(
        (
            l_off.dissipated_damping(),
            l_off.dissipated_friction(),
            l_off.tangential_stiffness_work()
        ),
        (0.0, 0.0, 0.0),
        "{SCENE}: without the ledger the per-contact terms must stay zero"
    );
    assert_eq!(
        (
            l_off.external_work().to_bits(),
            l_off.dissipated_viscous().to_bits(),
            l_off.initial_total().map(f64::to_bits)
        ),
        (
            l_on.external_work().to_bits(),
            l_on.dissipated_viscous().to_bits(),
            l_on.initial_total().map(f64::to_bits)
        ),
        "{SCENE}: the external and viscous work must not depend on the switch"
    );
}

#[test]
fn the_scene_key_energy_ledger_sets_the_switch() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(SCENE);
    let text = std::fs::read_to_string(&path).unwrap();
    for (value, expected) in [("false", false), ("true", true)] {
        let source = text.replacen(
            "[simulation]\n",
            &format!("[simulation]\nenergy_ledger = {value}\n"),
            1,
        );
        let sim = parse_scene(&source, &path)
            .unwrap_or_else(|e| panic!("{SCENE} with energy_ledger = {value}: {e}"));
        assert_eq!(
            sim.params.energy_ledger, expected,
            "{SCENE} with energy_ledger = {value}: switch {} (expected {expected})",
            sim.params.energy_ledger
        );
    }
}

fn without_kernel(params: &mut StepParams) {
    params.skips = Skips {
        sphere_kernel: false,
        ..params.skips
    };
}

#[test]
fn the_sphere_kernel_is_bit_identical_to_the_general_path_on_the_sphere_beds() {
    // With the ledger off the kernel takes its lean law (no ledger terms formed): also the same bits.
    for (file, ledger) in [
        (SCENE, true),
        ("scenes/sphere_bed_c_linear_5ms.toml", true),
        (SCENE, false),
        ("scenes/sphere_bed_c_linear_5ms.toml", false),
    ] {
        let mut on = scene_at(file);
        assert!(
            on.params.skips.sphere_kernel,
            "{file}: the kernel must be on by default"
        );
        on.params.energy_ledger = ledger;
        let mut off = scene_at(file);
        off.params.energy_ledger = ledger;
        without_kernel(&mut off.params);
        let (fast, general) = (run(on, STEPS), run(off, STEPS));
        if let Some(d) = first_difference(&fast, &general) {
            panic!("{file}, ledger {ledger}, {STEPS} steps, sphere kernel on against off: {d}");
        }
        // The bed is all free spheres: the kernel's world takes the sphere step, the other does not.
        let (params_on, params_off) = (scene_at(file).params, {
            let mut p = scene_at(file).params;
            without_kernel(&mut p);
            p
        });
        assert!(
            sphere_step_applies(&params_on, &fast) && !sphere_step_applies(&params_off, &general),
            "{file}: the sphere step must apply with the kernel on and not with it off"
        );
        assert_eq!(
            ledger_bits(&fast),
            ledger_bits(&general),
            "{file}, ledger {ledger}, {STEPS} steps: the ledger differs with the sphere kernel on ({:?}) and off ({:?})",
            fast.ledger(),
            general.ledger()
        );
        let touching = fast
            .contacts()
            .states()
            .iter()
            .filter(|c| c.is_active())
            .count();
        assert!(
            touching > 1000,
            "{file}: only {touching} overlapping contacts after {STEPS} steps (expected > 1000)"
        );
    }
}

#[test]
fn the_sphere_kernel_leaves_polyhedra_to_the_general_path() {
    // Every third body a sphere, the others polyhedra, with friction, damping and random spins.
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 2.0,
        ..bed::BedSpec::rocks([5, 5, 6], 3, 11)
    };
    let on = bed::build(&spec);
    let mut off = bed::build(&spec);
    without_kernel(&mut off.params);
    let steps = 300;
    let (fast, general) = (
        run_world(on.params, on.world, steps),
        run_world(off.params, off.world, steps),
    );
    if let Some(d) = first_difference(&fast, &general) {
        panic!("mixed bed {spec:?}, {steps} steps, sphere kernel on against off: {d}");
    }
    assert_eq!(
        ledger_bits(&fast),
        ledger_bits(&general),
        "mixed bed, {steps} steps: the ledger differs with the sphere kernel on and off"
    );
}

#[test]
fn the_sphere_step_gives_the_same_bits_on_one_and_two_threads() {
    // Every stage on the pool (thresholds 1), ledger on and off.
    for ledger in [true, false] {
        let on_threads = |threads: usize| {
            let mut sim = scene();
            sim.params.energy_ledger = ledger;
            sim.params.parallel = Parallelism {
                min_candidates: 1,
                min_bodies: 1,
            };
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap_or_else(|e| panic!("thread pool of {threads}: {e}"));
            let params = sim.params;
            let world = pool.install(|| run(sim, STEPS));
            assert!(
                sphere_step_applies(&params, &world),
                "{SCENE}: the sphere step must apply to the bed"
            );
            world
        };
        let (one, two) = (on_threads(1), on_threads(2));
        if let Some(d) = first_difference(&one, &two) {
            panic!("{SCENE}, ledger {ledger}, {STEPS} steps, one thread against two: {d}");
        }
        assert_eq!(
            ledger_bits(&one),
            ledger_bits(&two),
            "{SCENE}, ledger {ledger}, {STEPS} steps: the ledger differs on one ({:?}) and two ({:?}) threads",
            one.ledger(),
            two.ledger()
        );
    }
}
