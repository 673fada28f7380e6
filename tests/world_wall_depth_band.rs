//! The band of the smoothed wall (and pair) depth, bounded to where its derivation holds, and the overlap
//! statistic measured with the exact depth.
//!
//! `wall_depth_band = 10.0` in `scenes/cube_drop.toml` sank the cube most of its height into the floor,
//! exit 0: the smoothed depth the law sees falls short of the true one by up to 0.22 h, and the step's
//! overlap statistic, fed that smoothed depth, saw nothing. A band beyond
//! `polydem::contact::wall_depth::MAX_BAND` is now refused at load, and the statistic measures the
//! deepest vertex whatever the band.

use std::path::Path;

use polydem::contact::wall_depth::MAX_BAND;
use polydem::contact::WallDepth;
use polydem::math::Real;
use polydem::scene::{load_scene, parse_scene, SceneError};
use polydem::shape::Shape;
use polydem::world::{step, ContactKey, StepScratch, World};

fn cube_drop_text() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cube_drop.toml");
    std::fs::read_to_string(path).unwrap()
}

/// cube_drop with `line` added to its `[simulation]` table.
fn cube_drop_with(line: &str) -> String {
    cube_drop_text().replacen("[simulation]\n", &format!("[simulation]\n{line}\n"), 1)
}

/// The depth (m) of body 0's deepest vertex below the floor z = 0, from its vertices in the world frame.
fn deepest_below_floor(world: &World) -> Real {
    let Shape::Polyhedron(p) = world.shape(0) else {
        panic!("body 0 is not a polyhedron");
    };
    let pose = world.pose(0);
    p.vertices()
        .iter()
        .map(|v| -(pose * v).z)
        .fold(0.0, Real::max)
}

/// Bands above the bound are refused for walls and pairs, with the file, the line, the field and the
/// bound; the bound itself is accepted.
#[test]
fn smoothing_band_beyond_its_derivation_is_refused_with_the_bound() {
    for field in ["wall_depth_band", "pair_smoothing_band"] {
        for band in [10.0, MAX_BAND * (1.0 + 1e-9)] {
            let text = cube_drop_with(&format!("{field} = {band:e}"));
            let line = text.lines().position(|l| l.starts_with(field)).unwrap() + 1;
            match parse_scene(&text, Path::new("cube_drop_band.toml")) {
                Err(e @ SceneError::Invalid { .. }) => {
                    let message = e.to_string();
                    let want = format!("cube_drop_band.toml:{line}: simulation.{field}:");
                    assert!(
                        message.starts_with(&want) && message.contains(&format!("{MAX_BAND}")),
                        "band {band}: message {message:?}, expected it to start with {want:?} and state the bound {MAX_BAND}"
                    );
                }
                other => panic!("{field} = {band}: expected a refusal, got {other:?}"),
            }
        }
        let text = cube_drop_with(&format!("{field} = {MAX_BAND:e}"));
        let sim = parse_scene(&text, Path::new("cube_drop_band.toml"))
            .unwrap_or_else(|e| panic!("{field} = {MAX_BAND}: {e}"));
        let tol = sim.params.tolerances;
        if field == "wall_depth_band" {
            assert_eq!(tol.wall_depth, WallDepth::Smoothed { band: MAX_BAND });
        }
    }
}

/// cube_drop with the band of 10 the scene now refuses (set through the library, which still takes
/// it): the cube sinks deep into the floor, and the step's overlap statistic reports its exact depth
/// (the deepest vertex), far above the warning fraction, not the smoothed depth the law saw.
#[test]
fn overlap_statistic_reports_the_exact_depth_of_a_cube_sunk_by_a_wide_band() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cube_drop.toml");
    let mut sim = load_scene(&path).unwrap();
    sim.params.tolerances.wall_depth = WallDepth::Smoothed { band: 10.0 };
    let mut scratch = StepScratch::default();
    let mut last = None;
    let mut steps_warned = 0;
    for _ in 0..sim.steps {
        let report = step(&sim.params, &mut sim.world, &mut scratch).unwrap();
        steps_warned += usize::from(!report.overlap_warnings.is_empty());
        last = Some(report);
    }
    let report = last.unwrap();
    let length = sim.world.length_scale(0);
    let exact = deepest_below_floor(&sim.world);
    let law_depth = sim
        .world
        .contacts()
        .get(&ContactKey::Wall { body: 0, wall: 0 })
        .map(|s| s.geometry.depth)
        .unwrap_or(0.0);
    let measured = report.max_overlap_ratio * length;
    eprintln!(
        "band 10: deepest vertex {exact:.4e} m = {:.3} L = {:.3} of the cube's height, law (smoothed) depth {law_depth:.4e} m = {:.3e} L, overlap statistic {:.3} L, steps warned {steps_warned} of {}",
        exact / length,
        exact / 0.1,
        law_depth / length,
        report.max_overlap_ratio,
        sim.steps
    );
    assert!(
        (measured - exact).abs() <= 1e-12 * length,
        "overlap statistic {measured} m, deepest vertex {exact} m (L = {length} m, tolerance 1e-12 L)"
    );
    assert!(
        exact > 0.05 * length && law_depth < 0.5 * exact && steps_warned > 0,
        "exact depth {exact} m, law depth {law_depth} m, L = {length} m, steps with a deep-overlap warning {steps_warned}: expected the sunk cube reported"
    );
}
