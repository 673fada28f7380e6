//! Bad scenes give errors that name the file, the line and the field (bad input never panics).
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
    assert_eq!(sim.world.bodies().len(), 1);
    assert_eq!(sim.world.walls().len(), 1);
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
    assert_eq!(sim.world.bodies().len(), 2);
    assert_eq!(sim.tracked.len(), 2);
}

/// A scene with the sphere-bed features: Hertz–Mindlin from material constants, a box and a CSV body file.
const SPHERES: &str = r#"[simulation]
gravity = [0.0, 0.0, -9.81]
end_time = 0.001
output_interval = 0.0001
time_step = 1.0e-6
characteristic_speed = 1.0

[[material]]
name = "glass"
density = 2500.0
young_modulus = 1.0e9
poisson_ratio = 0.2

[[interaction]]
materials = ["glass", "glass"]
law = "hertz_mindlin"
restitution = 0.5
friction = 0.3
limit_force = true

[[box]]
name = "bin"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.01]
open = ["z+"]

[[body_file]]
path = "SPHERES_CSV"
material = "glass"
name_prefix = "g"
"#;

/// Writes `csv` next to the scene and loads the scene with `path = <csv file name>`.
fn load_with_csv(
    case: &str,
    scene: &str,
    csv: &str,
) -> (
    PathBuf,
    PathBuf,
    Result<polydem::scene::Simulation, SceneError>,
) {
    let dir = std::env::temp_dir().join(format!("polydem-scene-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv_name = format!("{case}.csv");
    std::fs::write(dir.join(&csv_name), csv).unwrap();
    let (path, result) = load(case, &scene.replace("SPHERES_CSV", &csv_name));
    (path, dir.join(csv_name), result)
}

const GOOD_CSV: &str = "# two glass beads\nid,x,y,z,radius,vx,vy,vz\n1,0.003,0.005,0.002,0.001,0,0,0\n2,0.007,0.005,0.002,0.001,0,0,-0.5\n";

#[test]
fn sphere_scene_with_box_and_body_file_loads() {
    let (_, _, result) = load_with_csv("spheres_ok", SPHERES, GOOD_CSV);
    let sim = result.expect("valid sphere scene");
    assert_eq!(sim.world.bodies().len(), 2);
    assert_eq!(sim.world.names(), vec!["g1".to_owned(), "g2".to_owned()]);
    assert_eq!(sim.world.walls().len(), 5, "an open-top box has five walls");
    assert_eq!(sim.world.bodies()[1].velocity.z, -0.5);
    // Walls face inwards: the x+ face's normal is −x and its plane passes through max.
    let xp = sim
        .world
        .walls()
        .iter()
        .find(|w| w.name == "bin.x+")
        .expect("wall bin.x+");
    assert_eq!(
        xp.normal_world(),
        polydem::math::Vector::new(-1.0, 0.0, 0.0)
    );
    assert!(xp.signed_distance(&polydem::math::Point::new(0.005, 0.0, 0.0)) > 0.0);
}

#[test]
fn bad_csv_row_names_the_csv_file_line_and_column() {
    let csv = GOOD_CSV.replace("2,0.007,0.005,0.002,0.001", "2,0.007,oops,0.002,0.001");
    let (path, csv_path, result) = load_with_csv("spheres_bad_row", SPHERES, &csv);
    let message = result.expect_err("bad CSV accepted").to_string();
    let csv_line = csv.lines().position(|l| l.contains("oops")).unwrap() + 1;
    let csv_location = format!("{}:{csv_line}: y:", csv_path.display());
    assert!(
        message.contains(&csv_location),
        "message {message:?} does not name the CSV file, line and column {csv_location:?}"
    );
    let scene_line = SPHERES.lines().position(|l| l.starts_with("path")).unwrap() + 1;
    assert_names(&message, &path, scene_line, "body_file[0].path");
}

#[test]
fn missing_csv_file_is_named_with_the_scene_line() {
    let (path, result) = load(
        "spheres_no_csv",
        &SPHERES.replace("SPHERES_CSV", "no-such-beads.csv"),
    );
    let message = result.expect_err("missing CSV accepted").to_string();
    let line = SPHERES.lines().position(|l| l.starts_with("path")).unwrap() + 1;
    assert_names(&message, &path, line, "body_file[0].path");
    assert!(message.contains("no-such-beads.csv"), "{message}");
}

#[test]
fn hertz_mindlin_needs_elastic_constants_and_refuses_stiffness() {
    let text = SPHERES.replace("young_modulus = 1.0e9\npoisson_ratio = 0.2\n", "");
    let (path, _, result) = load_with_csv("hm_no_young", &text, GOOD_CSV);
    let message = result.expect_err("missing E accepted").to_string();
    let line = text
        .lines()
        .position(|l| l.starts_with("name = \"glass\""))
        .unwrap()
        + 1;
    assert_names(&message, &path, line, "material[0].young_modulus");

    let text = SPHERES.replace(
        "law = \"hertz_mindlin\"",
        "law = \"hertz_mindlin\"\nnormal_stiffness = 1.0e6",
    );
    let (path, _, result) = load_with_csv("hm_stiffness", &text, GOOD_CSV);
    let message = result
        .expect_err("stiffness for hertz_mindlin accepted")
        .to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "normal_stiffness"),
        "interaction[0].normal_stiffness",
    );

    let text = SPHERES.replace("poisson_ratio = 0.2", "poisson_ratio = 0.7");
    let (path, _, result) = load_with_csv("hm_poisson", &text, GOOD_CSV);
    let message = result.expect_err("ν = 0.7 accepted").to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "poisson_ratio"),
        "material[0].poisson_ratio",
    );
}

#[test]
fn box_with_unknown_face_or_inverted_corners_is_refused() {
    let text = SPHERES.replace("open = [\"z+\"]", "open = [\"top\"]");
    let (path, _, result) = load_with_csv("box_face", &text, GOOD_CSV);
    let message = result.expect_err("unknown face accepted").to_string();
    assert_names(&message, &path, line_of(&text, "open"), "box[0].open");

    let text = SPHERES.replace("max = [0.01, 0.01, 0.01]", "max = [0.01, -0.01, 0.01]");
    let (path, _, result) = load_with_csv("box_corners", &text, GOOD_CSV);
    let message = result.expect_err("inverted box accepted").to_string();
    assert_names(&message, &path, line_of(&text, "max"), "box[0].max");

    let text = SPHERES.replace("open = [\"z+\"]", "open = [\"z+\"]\nmoving_face = \"z-\"");
    let (path, _, result) = load_with_csv("box_moving", &text, GOOD_CSV);
    let message = result
        .expect_err("moving face without velocity accepted")
        .to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "moving_face"),
        "box[0].velocity",
    );
}

#[test]
fn linear_law_takes_restitution_or_dashpot_not_both() {
    let text = edit("restitution", "restitution = 0.5\nnormal_damping = 2.0");
    let (path, result) = load("both_dampings", &text);
    let message = result.expect_err("both dampings accepted").to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "normal_damping"),
        "interaction[0].normal_damping",
    );
}

/// A density near the smallest f64 makes the effective mass, hence t_c and the derived step, underflow to
/// 0 s: refused at the `steps_per_contact` line (found by tests/fuzz_scene.rs).
#[test]
fn underflowing_derived_step_is_refused() {
    let text = edit("density", "density = 1e-308");
    let (path, result) = load("underflow_step", &text);
    let message = result.expect_err("zero time step accepted").to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "steps_per_contact"),
        "simulation.steps_per_contact",
    );
}

/// A finite but huge angular velocity overflows J ω: refused at the body's `angular_velocity` line (found by
/// tests/fuzz_scene.rs).
#[test]
fn overflowing_angular_momentum_is_refused() {
    // J ≈ 1e-7 m⁵ × ρ: with ρ = 1e306 kg/m³ and ω = 1e10 rad/s, J ω ≈ 1e309 overflows.
    let text = edit(
        "position = [0.0, 0.0, 0.2]",
        "position = [0.0, 0.0, 0.2]\nangular_velocity = [1e10, 0.0, 0.0]",
    )
    .replace("density = 2600.0", "density = 1e306");
    let (path, result) = load("huge_spin", &text);
    let message = result
        .expect_err("non-finite angular momentum accepted")
        .to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "angular_velocity"),
        "body[0].angular_velocity",
    );
}

#[test]
fn wall_depth_rule_and_band_are_read_and_bad_values_refused() {
    use polydem::contact::wall_depth::WallDepth;
    let (_, default) = load("wall_depth_default", VALID);
    assert_eq!(
        default.expect("valid scene").params.tolerances.wall_depth,
        WallDepth::default()
    );

    let text = edit(
        "steps_per_contact",
        "steps_per_contact = 50\nwall_depth_band = 3.0e-4",
    );
    let (_, banded) = load("wall_depth_band", &text);
    assert_eq!(
        banded
            .expect("scene with a band")
            .params
            .tolerances
            .wall_depth,
        WallDepth::Smoothed { band: 3.0e-4 }
    );

    let text = edit(
        "steps_per_contact",
        "steps_per_contact = 50\nwall_depth = \"deepest_vertex\"",
    );
    let (_, deepest) = load("wall_depth_deepest", &text);
    assert_eq!(
        deepest
            .expect("scene with the deepest-vertex rule")
            .params
            .tolerances
            .wall_depth,
        WallDepth::DeepestVertex
    );

    let text = edit(
        "steps_per_contact",
        "steps_per_contact = 50\nwall_depth = \"centroid\"",
    );
    let (path, result) = load("wall_depth_unknown", &text);
    let message = result
        .expect_err("unknown wall_depth rule accepted")
        .to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "wall_depth"),
        "simulation.wall_depth",
    );

    let text = edit(
        "steps_per_contact",
        "steps_per_contact = 50\nwall_depth = \"deepest_vertex\"\nwall_depth_band = 1.0e-4",
    );
    let (path, result) = load("wall_depth_band_ignored", &text);
    let message = result
        .expect_err("band with the deepest-vertex rule accepted")
        .to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "wall_depth_band"),
        "simulation.wall_depth_band",
    );

    let text = edit(
        "steps_per_contact",
        "steps_per_contact = 50\nwall_depth_band = -1.0",
    );
    let (path, result) = load("wall_depth_band_negative", &text);
    let message = result.expect_err("negative band accepted").to_string();
    assert_names(
        &message,
        &path,
        line_of(&text, "wall_depth_band"),
        "simulation.wall_depth_band",
    );
}

/// The valid scene with `keys` added to `[simulation]`.
fn with_keys(keys: &str) -> String {
    VALID.replace(
        "steps_per_contact = 50",
        &format!("steps_per_contact = 50\n{keys}"),
    )
}

/// `keys` added to the valid scene are refused, naming the file, the line starting with `line_prefix` and
/// `field`.
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

/// The pair smoothing the valid scene with `keys` reads.
fn read(case: &str, keys: &str) -> polydem::contact::PairSmoothing {
    load(case, &with_keys(keys))
        .1
        .unwrap_or_else(|e| panic!("{keys:?} refused: {e}"))
        .params
        .tolerances
        .pair_smoothing
}

#[test]
fn pair_smoothing_rule_and_band_are_read_and_bad_values_refused() {
    // The smoothed polyhedron-pair overlap (src/contact/pair_smoothing.rs); its physics gates are the
    // module's unit tests and `PolyEdgeFlat` in tests/polyhedral_energy_gates.rs.
    use polydem::contact::PairSmoothing;
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
