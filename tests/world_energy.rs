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

/// The energy sums of worlds marked as complementary parts (`World::count_only`: each counts the bodies
/// it owns and the pairs whose lower body it owns) add up to the whole world's, on the general step (a
/// mixed pile with friction, damping, a moving wall and global viscous damping) and on its sphere stage
/// (sphere bed a). Every world here holds every body, so all three step the same states; only the counting
/// differs. The parts' sums group the same terms differently, so they may differ from the whole's in
/// rounding: at most about n ε of the sum of the terms' magnitudes, n ≤ ~10^4 terms per sum, ε = 1.1e-16;
/// the tolerance is 1e-12 of the largest sum.
#[test]
fn shares_of_complementary_parts_add_up_to_the_whole_worlds_energy_sums() {
    use polydem::dynamics::ViscousDamping;
    use polydem::math::Vector;
    use polydem::world::EnergyShare;

    for (scene, steps) in [
        ("mixed_spheres_polyhedra.toml", 400),
        ("sphere_bed_a_hertz_5ms.toml", 100),
    ] {
        let mut sim = load_scene(&scene_path(scene)).expect("scene loads");
        sim.params.damping = ViscousDamping::MassProportional(5.0);
        sim.world
            .set_wall_velocity(0, Vector::new(0.0, 0.0, 0.01))
            .expect("a wall to move");
        let n = sim.world.body_count();
        let owners = [
            |i: usize| i.is_multiple_of(3),
            |i: usize| !i.is_multiple_of(3),
        ];
        let mut parts: Vec<_> = owners
            .iter()
            .map(|owns| {
                let mut world = sim.world.clone();
                world.count_only((0..n).map(owns).collect());
                (world, StepScratch::default())
            })
            .collect();
        let mut scratch = StepScratch::default();
        for _ in 0..steps {
            step(&sim.params, &mut sim.world, &mut scratch).expect("step");
            for (world, scratch) in &mut parts {
                step(&sim.params, world, scratch).expect("step");
            }
        }
        let mut added = EnergyShare::default();
        for (world, _) in &parts {
            added.add(&world.energy_share());
        }
        let expected = sim.world.energy_share();
        let fields = |s: &EnergyShare| -> Vec<(String, f64)> {
            let json = serde_json::to_value(s).expect("a share serialises");
            let mut out = Vec::new();
            let mut walk = vec![(String::new(), json)];
            while let Some((path, v)) = walk.pop() {
                match v {
                    serde_json::Value::Object(map) => {
                        walk.extend(map.into_iter().map(|(k, v)| (format!("{path}/{k}"), v)))
                    }
                    v => out.push((path, v.as_f64().expect("a number"))),
                }
            }
            out.sort_by(|a, b| a.0.cmp(&b.0));
            out
        };
        let (got, want) = (fields(&added), fields(&expected));
        let scale = want.iter().map(|(_, v)| v.abs()).fold(0.0, f64::max);
        for ((name, a), (_, b)) in got.iter().zip(&want) {
            let relative = (a - b).abs() / scale;
            assert!(
                relative <= 1e-12,
                "{scene}, {steps} steps, parts owning i % 3 == 0 and the rest: {name} added over the parts \
                 {a:e}, the whole world's {b:e}: {relative:.2e} of the largest sum {scale:e} (tolerance 1e-12)"
            );
        }
        let counted: Vec<f64> = want.iter().map(|(_, v)| *v).filter(|v| *v != 0.0).collect();
        assert!(
            counted.len() >= 8,
            "{scene}: only {} of the sums are non-zero ({want:?}): the test would not check them",
            counted.len()
        );
    }
}
