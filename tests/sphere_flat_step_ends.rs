//! What a caller of the flat sphere path reads between steps is the general step's state: after every
//! step the positions, velocities, angular momenta and loads the accessors return are the general step's
//! bits (not only the final state after a write-back, which `tests/sphere_flat_paths.rs` compares), and a
//! non-finite state is reported by the same step, for the same body and quantity, as the general step
//! reports it. It guards any change of the step's passes (such as leaving each step's second half kick to
//! the next step's first pass).

use polydem::dynamics::RigidBody;
use std::path::Path;

use polydem::math::Real;
use polydem::scene::{load_scene, Simulation};
use polydem::world::{step, SphereSim, StepError, StepScratch, World};

fn scene(file: &str) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let mut sim = load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    sim.params.energy_ledger = false;
    sim
}

/// Bed c, and its world for the general step with its scratch, and the flat path made from it.
fn bed_c() -> (Simulation, World, StepScratch, SphereSim) {
    let sim = scene("scenes/sphere_bed_c_linear_5ms.toml");
    let flat = SphereSim::from_world(&sim.world, &sim.params).expect("a sphere-only world");
    (sim.clone(), sim.world, StepScratch::default(), flat)
}

#[test]
fn accessors_show_every_step_end_as_the_general_step() {
    let (sim, mut world, mut scratch, mut flat) = bed_c();
    let n = world.bodies().len();
    // The projectile (last body), and a spread of bed spheres.
    let watched: Vec<usize> = (0..n).step_by(97).chain([n - 1]).collect();
    // The ball lands at step ~50: contacts open, persist and close in these steps.
    for k in 1..=120u64 {
        step(&sim.params, &mut world, &mut scratch).unwrap();
        flat.step().unwrap();
        for &i in &watched {
            let b = &world.bodies()[i];
            let pairs = [
                ("position", b.position.coords, flat.position(i).coords),
                ("velocity", b.velocity, flat.velocity(i)),
                (
                    "angular momentum",
                    b.angular_momentum,
                    flat.angular_momentum(i),
                ),
                ("force", world.loads().forces()[i], flat.forces()[i]),
                ("torque", world.loads().torques()[i], flat.torques()[i]),
            ];
            for (what, general, ours) in pairs {
                let bits = |v: &polydem::math::Vector| v.map(Real::to_bits);
                assert_eq!(
                    bits(&general),
                    bits(&ours),
                    "step {k}, sphere {i}, {what}: general step {general:?}, flat path {ours:?}"
                );
            }
        }
    }
}

/// On one thread and on two (where the step runs its passes as one job of the team from the first step
/// of a simulation made from a world with current loads).
#[test]
fn a_non_finite_state_is_the_general_steps_error() {
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| non_finite_state_is_the_general_steps_error(threads));
    }
}

fn non_finite_state_is_the_general_steps_error(threads: usize) {
    let (sim, mut world, mut scratch, mut flat) = bed_c();
    for _ in 0..10 {
        step(&sim.params, &mut world, &mut scratch).unwrap();
        flat.step().unwrap();
    }
    // A NaN velocity on a bed sphere, put in both states between steps.
    let body = 1234;
    let nan = |b: &mut RigidBody| b.velocity.y = Real::NAN;
    world.edit_body(body, nan).expect("a body");
    let mut broken = sim.world.clone();
    flat.write_back(&mut broken);
    broken.edit_body(body, nan).expect("a body");
    let mut flat = SphereSim::from_world(&broken, &sim.params).expect("a sphere-only world");
    let general_error = step(&sim.params, &mut world, &mut scratch).expect_err("NaN carried on");
    let flat_error = match flat.step() {
        Err(e) => e,
        Ok(_) => panic!("{threads} thread(s): the flat path carried the NaN on"),
    };
    let fields = |e: &StepError| match e {
        StepError::NonFinite {
            step,
            body,
            quantity,
            ..
        } => (*step, *body, *quantity),
        other => panic!("expected NonFinite, got {other:?}"),
    };
    assert_eq!(
        fields(&flat_error),
        fields(&general_error),
        "{threads} thread(s): flat path: {flat_error}; general step: {general_error}"
    );
    assert_eq!(
        fields(&flat_error).0,
        11,
        "{threads} thread(s): {flat_error}"
    );
}
