//! Gates on a many-body scene, `scenes/settling_box.toml` (20 random polyhedra falling into a box of
//! five walls):
//! - the run ends at rest, with no non-finite state (a step error would fail the run) and no body below the
//!   floor;
//! - the broad phase's candidate list, at every rebuild, equals the O(N²) definition, and at every step
//!   contains every pair whose bounding spheres overlap;
//! - two runs of the same scene are bit-identical (bodies and contact store).

use std::path::Path;

use polydem::math::{Point, Real};
use polydem::scene::{load_scene, Simulation};
use polydem::shape::Shape;
use polydem::world::broad_phase::brute_force_pairs;
use polydem::world::{step, StepScratch};

fn settling() -> Simulation {
    load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/settling_box.toml"))
        .expect("scene loads")
}

/// The lowest point of body `i` (m).
fn lowest_z(sim: &Simulation, i: usize) -> Real {
    let pose = sim.world.pose(i);
    match sim.world.shape(i) {
        Shape::Polyhedron(p) => p
            .vertices()
            .iter()
            .map(|v| (pose * v).z)
            .fold(Real::INFINITY, Real::min),
        Shape::Sphere(s) => pose.translation.vector.z - s.radius(),
        Shape::Plane(_) => unreachable!(),
        other => other.convex().expect("a body").aabb(&pose).mins.z,
    }
}

#[test]
fn polyhedra_settle_in_a_box_at_rest_above_the_floor_with_an_exact_broad_phase() {
    let mut sim = settling();
    let mut scratch = StepScratch::default();
    let mut rebuilds_checked = 0;
    let mut last_rebuilds = 0;
    let mut cost = std::time::Duration::ZERO;
    for _ in 0..sim.steps {
        let t = std::time::Instant::now();
        step(&sim.params, &mut sim.world, &mut scratch).expect("step");
        cost += t.elapsed();
        let w = &sim.world;
        let centres: Vec<Point> = w.bodies().iter().map(|b| b.position).collect();
        let bp = &w.broad_phase();
        if bp.rebuilds() != last_rebuilds {
            last_rebuilds = bp.rebuilds();
            // Positions do not change after the evaluation that rebuilt the list.
            let oracle = brute_force_pairs(&centres, w.radii(), bp.skin());
            assert_eq!(
                bp.pairs(),
                oracle.as_slice(),
                "broad phase differs from brute force at step {}",
                w.step_index()
            );
            rebuilds_checked += 1;
        }
        for pair in brute_force_pairs(&centres, w.radii(), 0.0) {
            assert!(
                bp.pairs().binary_search(&pair).is_ok(),
                "step {}: bounding spheres of {pair:?} overlap but the pair is not a candidate",
                w.step_index()
            );
        }
    }
    assert!(
        rebuilds_checked > 5,
        "only {rebuilds_checked} rebuilds: the bodies barely moved?"
    );

    let w = &sim.world;
    let g = w.gravity().norm();
    let size: Real = w.radii().iter().sum::<Real>() * 2.0 / w.radii().len() as Real;
    let rest_speed = 0.01 * (g * size).sqrt();
    for (i, b) in w.bodies().iter().enumerate() {
        let v = b.velocity.norm();
        let omega_r = b.angular_velocity().norm() * w.radii()[i];
        assert!(
            v < rest_speed && omega_r < rest_speed,
            "body {i} ('{}') not at rest at t = {} s: |v| = {v:e} m/s, |ω| r = {omega_r:e} m/s, threshold 0.01 √(g d) = {rest_speed:e} m/s",
            w.names()[i],
            w.time()
        );
        let z = lowest_z(&sim, i);
        assert!(
            z > -0.01 * size,
            "body {i} ('{}') reaches z = {z:e} m below the floor, tolerance 1 % of the mean size {size} m",
            w.names()[i]
        );
        assert!(
            b.position.z > 0.0,
            "body {i} centre below the floor: {}",
            b.position.z
        );
    }
    let per_body_step = cost.as_secs_f64() / (sim.steps as f64 * w.bodies().len() as f64);
    eprintln!(
        "settling box: {} steps, {:.3} µs per body per step, final kinetic energy {:e} J, balance {:e} J",
        sim.steps,
        per_body_step * 1e6,
        w.energy().translational_kinetic + w.energy().rotational_kinetic,
        w.energy().balance
    );
}

#[test]
fn two_runs_are_bit_identical() {
    let run = || {
        let mut sim = settling();
        let mut scratch = StepScratch::default();
        // Long enough for bodies to fall and collide with the floor and each other (t ≈ 0.2 s).
        for _ in 0..5000 {
            step(&sim.params, &mut sim.world, &mut scratch).expect("step");
        }
        sim
    };
    let (a, b) = (run(), run());
    assert!(
        a.world.contacts().states().iter().any(|s| s.is_active()),
        "no contact after 5000 steps"
    );
    for i in 0..a.world.bodies().len() {
        assert_eq!(
            a.world.bodies()[i],
            b.world.bodies()[i],
            "body {i} differs between two runs"
        );
    }
    assert_eq!(
        a.world.contacts(),
        b.world.contacts(),
        "contact stores differ"
    );
    assert_eq!(a.world.loads(), b.world.loads(), "loads differ");
}
