//! The small rockfill configuration shared by the rockfill tests (`tests/rockfill_*.rs`, included by path).

use polydem::math::Real;
use polydem::world::World;
use polydem_rockfill::config::ExperimentConfig;

/// The quick variant cut to a 1.2 m × 0.6 m × 0.6 m layer (about 25 rocks of 290 mm), short hold and
/// deposition, so that a whole experiment runs in about a second.
pub fn small() -> ExperimentConfig {
    let mut c = ExperimentConfig::quick();
    c.layer.length = 1.2;
    c.layer.width = 0.6;
    c.layer.height = 0.6;
    c.packing.hold_time = 0.02;
    c.packing.max_deposition_time = 1.0;
    c.packing.settle_speed = 0.2;
    c.packing.compaction_pressure = 1.0e4;
    c.rock.seed = 3;
    c
}

/// Fails if a rock's centre lies below the floor (z = 0) after packing: a rock pushed through it.
#[allow(dead_code)] // not every test file that includes this module packs a bed
pub fn assert_rocks_above_floor(world: &World) {
    let lowest = world
        .bodies()
        .iter()
        .map(|b| b.position.z)
        .fold(Real::INFINITY, Real::min);
    assert!(lowest > 0.0, "a rock centre below the floor: {lowest} m");
}
