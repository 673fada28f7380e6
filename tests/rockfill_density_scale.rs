//! Density (mass) scaling during packing (`[packing] packing_density_scale = s`, `crates/rockfill/src/packing.rs`):
//! the rocks pack with density s ρ, so the packing Δt (∝ √(m/k), through both the contact time and the
//! stability limit) grows by √s; after the hold the true masses and inertias are set again, bit for bit
//! those of an unscaled bed, the energy change is booked in the ledger, and the penetration keeps its own
//! (true-mass) Δt.

#[path = "support/rockfill_small.rs"]
mod support;

use polydem::math::{Real, Vector};
use polydem::shape::Shape;
use polydem::world::World;
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::experiment::generate_sample;
use polydem_rockfill::packing::{body_for, loose_world, packing_time_step, set_rock_density};
use polydem_rockfill::packing_run::pack;
use polydem_rockfill::penetration::penetration_time_step;
use support::small;

fn loose(config: &ExperimentConfig) -> World {
    let sample = generate_sample(config).unwrap();
    let top = config.layer.height * config.packing.generation_height_factor;
    loose_world(config, &sample.rocks, top).unwrap()
}

/// The mass and principal inertia a rock of `world` has at the configuration's true density.
fn true_mass_properties(config: &ExperimentConfig, world: &World, i: usize) -> (Real, Vector) {
    let Shape::Polyhedron(shape) = world.shape(i) else {
        panic!("body {i} is not a polyhedron");
    };
    let b = body_for(shape, &world.pose(i), config.rock.density).unwrap();
    (b.mass, b.inertia.0)
}

#[test]
fn density_scale_multiplies_masses_and_inertias_by_s_and_the_packing_step_by_sqrt_s() {
    let mut config = small();
    config.packing.packing_steps_per_contact = Some(10.0);
    let mut world = loose(&config);
    for k in 0..world.body_count() {
        let v = Vector::new(0.0, 0.1, -1.0 - 0.01 * k as Real);
        world.set_body_velocity(k, v).expect("a rock");
        let w = Vector::new(0.3, -0.2, 0.1 * k as Real);
        world.set_body_angular_velocity(k, w).expect("a rock");
    }
    let before = world.bodies().to_vec();
    let e0 = world.energy();
    let (dt0, tc0) = packing_time_step(&config, &world).unwrap();
    for s in [4.0, 16.0, 100.0] {
        let mut scaled = world.clone();
        let changed = set_rock_density(&mut scaled, config.rock.density * s).unwrap();
        let (dt, tc) = packing_time_step(&config, &scaled).unwrap();
        for (measured, reference, what) in [(dt, dt0, "packing Δt"), (tc, tc0, "contact time")] {
            let ratio = measured / reference;
            assert!(
                (ratio - s.sqrt()).abs() <= 1e-12 * s.sqrt(),
                "s = {s}: {what} {measured} s against {reference} s unscaled: ratio {ratio}, expected √s = {} \
                 (tol 1e-12 relative)",
                s.sqrt()
            );
        }
        for (i, (b, b0)) in scaled.bodies().iter().zip(before.iter()).enumerate() {
            let rel = |a: Real, e: Real| (a - e).abs() / e.abs().max(Real::MIN_POSITIVE);
            assert!(
                rel(b.mass, s * b0.mass) <= 1e-14,
                "s = {s}, rock {i}: mass {} kg, expected s × {} kg (tol 1e-14 relative)",
                b.mass,
                b0.mass
            );
            for k in 0..3 {
                assert!(
                    rel(b.inertia.0[k], s * b0.inertia.0[k]) <= 1e-14,
                    "s = {s}, rock {i}: principal moment {k} {} kg m², expected s × {} (tol 1e-14 relative)",
                    b.inertia.0[k],
                    b0.inertia.0[k]
                );
            }
            let (w, w0) = (b.angular_velocity(), b0.angular_velocity());
            assert!(
                b.velocity == b0.velocity && (w - w0).norm() <= 1e-14 * w0.norm(),
                "s = {s}, rock {i}: velocity {:?} -> {:?}, angular velocity {w0:?} -> {w:?} (kept, tol 1e-14)",
                b0.velocity,
                b.velocity
            );
        }
        // Kinetic and gravitational energy are proportional to the masses (no contacts: no elastic energy).
        let expected = (s - 1.0) * e0.mechanical();
        assert!(
            (changed - expected).abs() <= 1e-12 * expected.abs(),
            "s = {s}: mechanical energy change {changed} J, expected (s − 1) E = {expected} J (tol 1e-12)"
        );
    }
}

#[test]
fn packing_with_density_scale_ends_at_the_true_masses_with_the_ledger_closed_and_the_true_steps() {
    let s = 16.0;
    let mut config = small();
    config.packing.packing_steps_per_contact = Some(10.0);
    config.packing.drop_speed = Some(2.0);
    let unscaled = loose(&config);
    let (dt_true, _) = packing_time_step(&config, &unscaled).unwrap();
    let pen_true = penetration_time_step(&config, &unscaled).unwrap();
    config.packing.packing_density_scale = Some(s);
    config.packing.restore_time = Some(0.01);
    let mut world = loose(&config);
    let report = pack(&config, &mut world, |_, _, _| {}).unwrap();

    let ratio = report.dt / dt_true;
    assert!(
        (ratio - s.sqrt()).abs() <= 1e-12 * s.sqrt(),
        "packing Δt {} s against the true-mass {dt_true} s: ratio {ratio}, expected √{s} (tol 1e-12)",
        report.dt
    );
    assert_eq!(
        report.restore_dt, dt_true,
        "restore Δt {} s, expected the true-mass packing Δt {dt_true} s",
        report.restore_dt
    );
    // The density ramps from s ρ to ρ over the first half of restore_time (Δt from √s dt_true down to
    // dt_true), the second half runs at dt_true.
    let restore_time = config.packing.restore_time.unwrap();
    let (fewest, most) = (
        (restore_time / (s.sqrt() * dt_true)).floor() as u64,
        (restore_time / dt_true).ceil() as u64 + 1,
    );
    assert!(
        (fewest..=most).contains(&report.restore_steps),
        "restore: {} steps over {restore_time} s, expected between {fewest} (all at √s Δt) and {most} (all at \
         the true Δt {dt_true} s)",
        report.restore_steps
    );
    for i in 0..world.bodies().len() {
        let (mass, inertia) = true_mass_properties(&config, &world, i);
        let b = &world.bodies()[i];
        assert!(
            b.mass == mass && b.inertia.0 == inertia,
            "rock {i}: mass {} kg, moments {:?} after the restore; true {mass} kg, {inertia:?} (bit for bit)",
            b.mass,
            b.inertia.0
        );
    }
    let pen = penetration_time_step(&config, &world).unwrap();
    assert_eq!(
        pen, pen_true,
        "penetration Δt {pen} s from the restored bed, {pen_true} s from the unscaled rocks"
    );
    // The mass change is booked as external work: the balance does not jump at the restore. Without the
    // booking it would move by (1 − 1/s) of the scaled bed's kinetic + gravitational energy (≈ 0.94 of its
    // potential energy here).
    let jump = report.ledger_balance_relative[2] - report.ledger_balance_relative[1];
    assert!(
        jump.abs() < 0.01,
        "ledger balance / initial potential: {} after the hold, {} after the restore (change {jump}, tol 0.01)",
        report.ledger_balance_relative[1],
        report.ledger_balance_relative[2]
    );
    support::assert_rocks_above_floor(&world);
}

#[test]
fn the_density_scaled_file_is_paper_toml_but_for_its_100_mm_lines() {
    let path = "scenes/rockfill/paper_density_scaled.toml";
    let scaled = ExperimentConfig::parse(
        include_str!("../scenes/rockfill/paper_density_scaled.toml"),
        path,
    )
    .unwrap();
    assert_eq!(scaled.packing.packing_density_scale, Some(16.0), "{path}");
    assert_eq!(scaled.packing.restore_time, Some(0.1), "{path}");
    let mut expected = ExperimentConfig::paper();
    expected.rock.mean_size = 0.10;
    expected.packing.max_deposition_time = 2.0;
    expected.packing.packing_density_scale = Some(16.0);
    expected.packing.restore_time = Some(0.1);
    expected.packing.generation_height_factor = 2.75;
    expected.sleeping.penetration = true;
    expected.sleeping.wake_contact_fraction = 0.03;
    assert_eq!(
        scaled, expected,
        "{path} differs from paper.toml elsewhere than in mean_size, max_deposition_time, the density scaling, \
         the generation height factor and the penetration's sleeping"
    );
}
