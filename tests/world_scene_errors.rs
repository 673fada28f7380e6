//! Bad scenes give errors that name the file, the line and the field (issue 4: bad input never panics).
//! Each case edits one line of a valid scene; the expected line number is found in the text, not typed.

use std::path::PathBuf;

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

[[wall]]
name = "floor"
material = "rock"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"#;

/// Writes `text` to a fresh file named after the case and loads it.
fn load(case: &str, text: &str) -> (PathBuf, Result<polydem::scene::Simulation, SceneError>) {
    let dir = std::env::temp_dir().join(format!("polydem-scene-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{case}.toml"));
    std::fs::write(&path, text).unwrap();
    let result = load_scene(&path);
    (path, result)
}

/// The 1-based line of the first line of `text` that starts with `prefix`.
fn line_of(text: &str, prefix: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line starts with {prefix:?}"))
        + 1
}

/// Replaces the line starting with `prefix` by `new`.
fn edit(prefix: &str, new: &str) -> String {
    let line = line_of(VALID, prefix);
    VALID
        .lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { new } else { l })
        .collect::<Vec<_>>()
        .join("\n")
}

fn assert_names(message: &str, path: &std::path::Path, line: usize, field: &str) {
    let location = format!("{}:{line}:", path.display());
    assert!(
        message.contains(&location),
        "message {message:?} does not name file and line {location:?}"
    );
    assert!(
        message.contains(field),
        "message {message:?} does not name the field {field:?}"
    );
}

#[test]
fn the_valid_scene_loads() {
    let (_, result) = load("valid", VALID);
    let sim = result.expect("valid scene");
    assert_eq!(sim.world.bodies.len(), 1);
    assert_eq!(sim.world.walls.len(), 1);
}

#[test]
fn unknown_field_names_file_line_and_field() {
    let text = edit("density", "density = 2600.0\ncolour = \"grey\"");
    let (path, result) = load("unknown_field", &text);
    let message = result.expect_err("unknown field accepted").to_string();
    assert_names(&message, &path, line_of(&text, "colour"), "colour");
}

#[test]
fn missing_field_is_named() {
    let text = edit("density", "");
    let (path, result) = load("missing_field", &text);
    let message = result.expect_err("missing density accepted").to_string();
    // toml reports a missing field at the table that lacks it.
    assert!(message.contains(&path.display().to_string()), "{message}");
    assert!(message.contains("density"), "{message}");
}

#[test]
fn negative_stiffness_names_file_line_and_field() {
    let text = edit("normal_stiffness", "normal_stiffness = -1.0e6");
    let (path, result) = load("negative_stiffness", &text);
    let message = result.expect_err("negative stiffness accepted").to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "normal_stiffness"),
        "interaction[0].normal_stiffness",
    );
    assert!(message.contains("positive"), "{message}");
}

#[test]
fn restitution_outside_zero_one_is_refused() {
    for bad in ["0.0", "1.5"] {
        let text = edit("restitution", &format!("restitution = {bad}"));
        let (path, result) = load("bad_restitution", &text);
        let message = result.expect_err("bad restitution accepted").to_string();
        assert_names(
            &message,
            &path,
            line_of(&text, "restitution"),
            "interaction[0].restitution",
        );
    }
}

#[test]
fn nan_parameter_names_file_line_and_field() {
    let text = edit("density", "density = nan");
    let (path, result) = load("nan_density", &text);
    let message = result.expect_err("NaN density accepted").to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "density"),
        "material[0].density",
    );
}

#[test]
fn coplanar_points_name_the_shape_the_body_and_the_line() {
    let text = edit(
        "points",
        "points = [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.1, 0.1, 0.0]]",
    );
    let (path, result) = load("coplanar", &text);
    let message = result.expect_err("coplanar points accepted").to_string();
    assert_names(&message, &path, line_of(&text, "points"), "shape[0].points");
    assert!(message.contains("coplanar"), "{message}");
    assert!(
        message.contains("'t1'"),
        "message does not name the body using the shape: {message}"
    );
}

#[test]
fn too_few_points_are_refused() {
    let text = edit(
        "points",
        "points = [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]]",
    );
    let (path, result) = load("too_few", &text);
    let message = result.expect_err("3 points accepted").to_string();
    assert_names(&message, &path, line_of(&text, "points"), "shape[0].points");
}

#[test]
fn unstable_time_step_is_refused_with_the_limit() {
    let text = edit("steps_per_contact", "time_step = 0.01");
    let (path, result) = load("unstable", &text);
    let message = result.expect_err("unstable time step accepted").to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "time_step"),
        "simulation.time_step",
    );
    assert!(message.contains("stability limit"), "{message}");
    // The stated limit is the one the derived step is checked against.
    let (_, valid) = load("valid_for_limit", VALID);
    let limit = valid.unwrap().time_step.stability_limit;
    assert!(
        message.contains(&format!("{limit:e}")),
        "message {message:?} does not state the limit {limit:e}"
    );
}

#[test]
fn missing_file_is_named() {
    let path = std::env::temp_dir().join("polydem-no-such-scene-3141.toml");
    let message = load_scene(&path)
        .expect_err("missing file accepted")
        .to_string();
    assert!(message.contains(&path.display().to_string()), "{message}");
    assert!(message.contains("cannot read"), "{message}");
}

#[test]
fn unknown_material_of_a_body_is_named() {
    let text = VALID.replace(
        "material = \"rock\"\nposition",
        "material = \"granite\"\nposition",
    );
    let (path, result) = load("unknown_material", &text);
    let message = result.expect_err("unknown material accepted").to_string();
    let line = text.lines().position(|l| l.contains("granite")).unwrap() + 1;
    assert_names(&message, &path, line, "body[0].material");
}

#[test]
fn the_documented_example_loads() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/scene-format.md"))
        .unwrap();
    let start = doc.find("```toml\n").expect("example block") + "```toml\n".len();
    let end = start + doc[start..].find("```").expect("end of example");
    let (path, result) = load("doc_example", &doc[start..end]);
    let sim = result.unwrap_or_else(|e| {
        panic!(
            "example of docs/scene-format.md ({}) fails: {e}",
            path.display()
        )
    });
    assert_eq!(sim.world.bodies.len(), 2);
    assert_eq!(sim.tracked.len(), 2);
}
