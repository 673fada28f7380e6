//! The scene keys of the smoothed polyhedron-pair overlap (`src/contact/pair_smoothing.rs`):
//! `simulation.pair_smoothing` and `simulation.pair_smoothing_band` are read, and bad values are refused with
//! the file, the line and the field named. The physics gates of the smoothing are in the module's unit tests
//! (the force is the gradient of the smoothed overlap through a vertex tie) and in
//! `tests/polyhedral_energy_gates.rs` (`PolyEdgeFlat`: an edge landing flat on a face, second order).

use std::path::PathBuf;

use polydem::contact::PairSmoothing;
use polydem::scene::{load_scene, SceneError};

const VALID: &str = r#"[simulation]
gravity = [0.0, 0.0, -9.81]
end_time = 0.1
output_interval = 0.01
steps_per_contact = 50

[[material]]
name = "rock"
density = 2600.0

[[interaction]]
materials = ["rock", "rock"]
law = "linear"
normal_stiffness = 1.0e6
restitution = 0.5
tangential_stiffness = 5.0e5
friction = 0.5

[[shape]]
name = "tetra"
kind = "polyhedron"
points = [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]

[[body]]
name = "t1"
shape = "tetra"
material = "rock"
position = [0.0, 0.0, 0.2]
"#;

fn load(case: &str, text: &str) -> (PathBuf, Result<polydem::scene::Simulation, SceneError>) {
    let dir = std::env::temp_dir().join(format!("polydem-pair-smoothing-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{case}.toml"));
    std::fs::write(&path, text).unwrap();
    let result = load_scene(&path);
    (path, result)
}

fn with_keys(keys: &str) -> String {
    VALID.replace(
        "steps_per_contact = 50",
        &format!("steps_per_contact = 50\n{keys}"),
    )
}

fn line_of(text: &str, prefix: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line starts with {prefix:?}"))
        + 1
}

fn refused(case: &str, keys: &str, line_prefix: &str, field: &str) {
    let text = with_keys(keys);
    let (path, result) = load(case, &text);
    let message = result
        .err()
        .unwrap_or_else(|| panic!("{keys:?} accepted"))
        .to_string();
    let location = format!("{}:{}:", path.display(), line_of(&text, line_prefix));
    assert!(
        message.contains(&location) && message.contains(field),
        "{keys:?}: message {message:?} does not name {location:?} and the field {field:?}"
    );
}

fn read(case: &str, keys: &str) -> PairSmoothing {
    load(case, &with_keys(keys))
        .1
        .unwrap_or_else(|e| panic!("{keys:?} refused: {e}"))
        .params
        .tolerances
        .pair_smoothing
}

#[test]
fn pair_smoothing_rule_and_band_are_read_and_bad_values_refused() {
    assert_eq!(read("default", ""), PairSmoothing::default());
    assert_eq!(
        read("band", "pair_smoothing_band = 3.0e-4"),
        PairSmoothing::Smoothed { band: 3.0e-4 }
    );
    assert_eq!(
        read("smoothed", "pair_smoothing = \"smoothed\""),
        PairSmoothing::default()
    );
    assert_eq!(
        read("exact", "pair_smoothing = \"exact\""),
        PairSmoothing::Exact
    );
    refused(
        "unknown",
        "pair_smoothing = \"blended\"",
        "pair_smoothing",
        "simulation.pair_smoothing",
    );
    refused(
        "band_with_exact",
        "pair_smoothing = \"exact\"\npair_smoothing_band = 1.0e-4",
        "pair_smoothing_band",
        "simulation.pair_smoothing_band",
    );
    refused(
        "negative_band",
        "pair_smoothing_band = -1.0",
        "pair_smoothing_band",
        "simulation.pair_smoothing_band",
    );
    refused(
        "nan_band",
        "pair_smoothing_band = nan",
        "pair_smoothing_band",
        "simulation.pair_smoothing_band",
    );
}
