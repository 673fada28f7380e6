//! Gate: two polyhedra colliding vertex-to-face, elastically, through the whole engine
//! (`scenes/two_polyhedra_elastic.toml`, `World::step`): the energy ledger's balance stays within 1e-4 of
//! the initial energy at Δt = t_c/200, the collision really happens (the bodies separate spinning), and the
//! total linear momentum is conserved.

use std::path::Path;

use polydem::scene::load_scene;
use polydem::world::{step, StepScratch};

fn scene_path(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

#[test]
fn elastic_vertex_face_collision_conserves_energy_through_the_engine() {
    let path = scene_path("two_polyhedra_elastic.toml");
    let mut sim = load_scene(&path).expect("scene loads");
    assert!(sim.time_step.derived);
    let ratio = sim.time_step.contact_time / sim.time_step.dt;
    assert!(
        (ratio - 200.0).abs() < 1e-9,
        "dt = t_c/{ratio}, expected t_c/200"
    );
    let e0 = sim.world.energy().mechanical();
    let p0 = sim.world.linear_momentum();
    let mut scratch = StepScratch::default();
    let (mut worst, mut contact_steps) = (0.0f64, 0u64);
    for _ in 0..sim.steps {
        let report = step(&sim.params, &mut sim.world, &mut scratch).expect("step");
        contact_steps += report.contacts as u64;
        worst = worst.max(sim.world.energy().balance.abs() / e0);
    }
    let end = sim.world.energy();
    assert!(contact_steps > 100, "the bodies touched during only {contact_steps} steps (expected a full contact of ~200 steps)");
    assert!(
        end.rotational_kinetic > 1e-2 * e0,
        "rotational energy after the eccentric impact {:e} J, expected > 1e-2 E0 = {:e} J",
        end.rotational_kinetic,
        1e-2 * e0
    );
    assert_eq!(
        sim.world.contacts().len(),
        1,
        "the pair stays a broad-phase candidate"
    );
    assert!(
        worst <= 1e-4,
        "max |balance|/E0 = {worst:e} over {} steps (E0 = {e0} J, dt = {:e} s), tolerance 1e-4",
        sim.steps,
        sim.params.dt
    );
    let dp = (sim.world.linear_momentum() - p0).norm();
    let scale = sim.world.bodies().iter().map(|b| b.mass * 1.0).sum::<f64>();
    assert!(
        dp <= 1e-12 * scale,
        "momentum change {dp:e} kg·m/s, tolerance 1e-12 × Σm·1 m/s = {:e}",
        1e-12 * scale
    );
    eprintln!(
        "two-body elastic: max |balance|/E0 = {worst:e}, final rotational share {:.4}",
        end.rotational_kinetic / e0
    );
}
