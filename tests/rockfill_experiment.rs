//! The rockfill chain on a small bed: packing keeps every rock in the container and the ledger
//! closed to the measured level, the saved bed reloads to the same state, and the penetration run ends
//! with the projectile through the layer, finite state and a closed ledger.

use polydem::shape::Shape;
use polydem_rockfill::experiment::{generate_sample, run_experiment, BedSource};
use polydem_rockfill::packing::{load_bed, loose_world, save_bed, KEPT_WALLS};
use polydem_rockfill::packing_run::pack;
use polydem_rockfill::penetration::Outcome;

#[path = "support/rockfill_small.rs"]
mod rockfill_small;
use rockfill_small::small;

#[test]
fn packed_bed_stays_in_the_container_and_reloads_bit_for_bit() {
    let config = small();
    let sample = generate_sample(&config).unwrap();
    let top = config.layer.height * config.packing.generation_height_factor;
    let mut world = loose_world(&config, &sample.rocks, top).unwrap();
    let report = pack(&config, &mut world, |_, _, _| {}).unwrap();
    let d = config.rock.mean_size;
    // Every vertex inside the box, up to the largest overlap a wall contact may have (1 % of the size).
    let tol = 0.01 * d;
    for i in 0..world.bodies().len() {
        let Shape::Polyhedron(p) = world.shape(i) else {
            panic!("rock {i} is not a polyhedron")
        };
        let aabb = p.aabb(&world.pose(i));
        let (lo, hi) = (aabb.mins, aabb.maxs);
        assert!(
            lo.x > -tol
                && lo.y > -tol
                && lo.z > -tol
                && hi.x < config.layer.length + tol
                && hi.y < config.layer.width + tol
                && hi.z < report.top_wall + tol,
            "rock {i} box {lo} – {hi} leaves the container (top wall {}), tol {tol}",
            report.top_wall
        );
    }
    assert!(
        report.max_overlap_ratio < 0.05,
        "max overlap/size {}",
        report.max_overlap_ratio
    );
    // The ledger of packing closes to 1 % of the rocks' initial potential energy (measured: 1.4e-3 to
    // 1.7e-3 after every stage, seeds 3–5 of this bed in three rock orders; before the servo-driven top
    // wall's work was booked with the velocity that moves it, compaction missed half of that work: 2e-2 to
    // 1.8e-1 by seed and order).
    for (stage, b) in ["deposition", "compaction", "hold"]
        .iter()
        .zip(report.ledger_balance_relative)
    {
        assert!(
            b.abs() < 1e-2,
            "{stage}: ledger balance / initial potential {b}, tol 1e-2"
        );
    }
    let dir = std::env::temp_dir().join(format!("polydem_bed_{}", std::process::id()));
    save_bed(&world, &dir).unwrap();
    let loaded = load_bed(&config, &dir).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(loaded.bodies().len(), world.bodies().len());
    assert_eq!(loaded.walls().len(), KEPT_WALLS + 2);
    for (i, (a, b)) in world.bodies().iter().zip(loaded.bodies()).enumerate() {
        let scale = world.length_scale(i);
        assert_eq!(a.velocity, b.velocity, "rock {i} velocity");
        assert_eq!(
            a.angular_momentum, b.angular_momentum,
            "rock {i} angular momentum"
        );
        assert!(
            (a.position - b.position).norm() <= 1e-12 * scale,
            "rock {i} centre moved by {} on reload",
            (a.position - b.position).norm()
        );
        assert!(((a.mass - b.mass) / a.mass).abs() < 1e-12, "rock {i} mass");
        // Same solid in the world: the world vertices of the reloaded hull match the original's.
        let (Shape::Polyhedron(pa), Shape::Polyhedron(pb)) = (world.shape(i), loaded.shape(i))
        else {
            panic!("rock {i}")
        };
        for v in pb.vertices() {
            let w = loaded.pose(i) * v;
            let nearest = pa
                .vertices()
                .iter()
                .map(|u| (world.pose(i) * u - w).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest <= 1e-12 * scale,
                "rock {i}: reloaded vertex {w} is {nearest} from the original"
            );
        }
    }
}

#[test]
fn projectile_passes_through_a_small_bed_with_a_closed_ledger() {
    let config = small();
    let mut progress = |_: &str, _: String| {};
    let r = run_experiment(&config, BedSource::Generate { save: None }, &mut progress).unwrap();
    let p = &r.penetration;
    assert_eq!(
        p.outcome,
        Outcome::Exited,
        "outcome {:?} after {} steps",
        p.outcome,
        p.steps
    );
    assert!(p
        .rows
        .iter()
        .all(|row| row.velocity.iter().all(|v| v.is_finite())));
    assert!(
        p.residual_speed < config.impact.speed && p.residual_speed > 0.5 * config.impact.speed,
        "residual speed {} for an impact at {}",
        p.residual_speed,
        config.impact.speed
    );
    // Energy: the ledger closes to 1e-3 of the projectile's kinetic energy (measured −3.8e-4 on the quick
    // variant).
    assert!(
        p.ledger_balance_relative.abs() < 1e-3,
        "ledger balance / initial projectile energy {}, tol 1e-3",
        p.ledger_balance_relative
    );
    assert!(
        p.rows.iter().any(|row| row.contacts > 0),
        "the projectile never touched a rock"
    );
}
