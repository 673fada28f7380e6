//! Gate: a sphere dropped on a wall through the whole engine (`scenes/sphere_bounce.toml`,
//! linear spring–dashpot) rebounds with the restitution given in the scene, within 1 %, at each bounce.

use std::path::Path;

use polydem::scene::load_scene;
use polydem::world::{step, StepScratch};

#[test]
fn sphere_on_wall_rebounds_with_the_input_restitution() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_bounce.toml");
    let mut sim = load_scene(&path).expect("scene loads");
    // The input restitution, read back from the scene file itself (not retyped here).
    let text = std::fs::read_to_string(&path).unwrap();
    let table: toml::Table = text.parse().unwrap();
    let expected = table["interaction"][0]["restitution"].as_float().unwrap();
    let mut scratch = StepScratch::default();
    let mut in_contact = false;
    let mut v_before = 0.0;
    let mut ratios = Vec::new();
    for _ in 0..sim.steps {
        let v_previous = sim.world.bodies()[0].velocity.z;
        let report = step(&sim.params, &mut sim.world, &mut scratch).expect("step");
        let touching = report.contacts > 0;
        if touching && !in_contact {
            v_before = v_previous;
        }
        if !touching && in_contact {
            ratios.push(-sim.world.bodies()[0].velocity.z / v_before);
        }
        in_contact = touching;
    }
    assert!(
        ratios.len() >= 2,
        "only {} bounces in {} s",
        ratios.len(),
        sim.end_time
    );
    for (k, e) in ratios.iter().enumerate() {
        assert!(
            (e - expected).abs() <= 0.01 * expected,
            "bounce {k}: measured restitution {e}, input {expected}, tolerance 1 % (dt = {:e} s, t_c = {:e} s)",
            sim.params.dt,
            sim.time_step.contact_time
        );
    }
    eprintln!("sphere on wall: restitution per bounce {ratios:?}, input {expected}");
}
