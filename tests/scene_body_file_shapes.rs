//! `[[body_file]]` with a shape table: each row names a `[[shape]]` and gives the pose of its own frame
//! and its velocities. The example scene `scenes/polyhedra_from_file.toml` must place every body exactly
//! as the same rows written as `[[body]]` entries do, and each kind of bad row must be refused with the
//! CSV file, its line and the column, together with the scene's line of `path`.

use std::path::{Path, PathBuf};

use polydem::math::{Point, Rotation, Vector};
use polydem::scene::{load_scene, parse_scene, SceneError, Simulation};

fn example_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/polyhedra_from_file.toml")
}

/// The data rows of a CSV as (column name → text) maps, with the header's column order.
fn csv_rows(text: &str) -> Vec<Vec<(String, String)>> {
    let mut lines = text.lines().filter(|l| !l.trim_start().starts_with('#'));
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(str::to_owned))
                .collect()
        })
        .collect()
}

fn get(row: &[(String, String)], name: &str) -> f64 {
    let text = &row.iter().find(|(c, _)| c == name).unwrap().1;
    text.parse().unwrap()
}

fn text(row: &[(String, String)], name: &str) -> String {
    row.iter().find(|(c, _)| c == name).unwrap().1.clone()
}

/// The example's rows written as `[[body]]` entries instead of the `[[body_file]]`.
fn as_body_entries(scene: &str, rows: &[Vec<(String, String)>]) -> String {
    let head = &scene[..scene.find("\n[[body_file]]").unwrap() + 1];
    let mut out = head.to_owned();
    for row in rows {
        let v3 = |a: &str, b: &str, c: &str| {
            format!("[{:?}, {:?}, {:?}]", get(row, a), get(row, b), get(row, c))
        };
        out += &format!(
            "[[body]]\nname = \"rock_{}\"\nshape = \"{}\"\nmaterial = \"rock\"\nposition = {}\norientation = [{:?}, {:?}, {:?}, {:?}]\nvelocity = {}\nangular_velocity = {}\ntrack = true\n\n",
            text(row, "id"),
            text(row, "shape"),
            v3("x", "y", "z"),
            get(row, "qw"),
            get(row, "qx"),
            get(row, "qy"),
            get(row, "qz"),
            v3("vx", "vy", "vz"),
            v3("wx", "wy", "wz"),
        );
    }
    out
}

#[test]
fn example_scene_places_the_file_poses_exactly() {
    let path = example_path();
    let sim = load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let csv = std::fs::read_to_string(path.with_extension("csv")).unwrap();
    let rows = csv_rows(&csv);
    assert_eq!(
        sim.world.bodies().len(),
        rows.len(),
        "one body per row of {csv:?}"
    );
    for row in &rows {
        let name = format!("rock_{}", text(row, "id"));
        let i = sim.world.names().iter().position(|n| *n == name).unwrap();
        let body = &sim.world.bodies()[i];
        let frame = &sim.frames[i];
        let q = Rotation::from_quaternion(nalgebra::Quaternion::new(
            get(row, "qw"),
            get(row, "qx"),
            get(row, "qy"),
            get(row, "qz"),
        ));
        let origin = Point::new(get(row, "x"), get(row, "y"), get(row, "z"));
        // The principal frame sits at `frame` in the shape's own frame, which the row places at (origin, q).
        let expected_position = origin + q * frame.translation.vector;
        let expected_orientation = q * frame.rotation;
        assert_eq!(body.position, expected_position, "{name}: row {row:?}");
        assert_eq!(
            body.orientation, expected_orientation,
            "{name}: row {row:?}"
        );
        let v = Vector::new(get(row, "vx"), get(row, "vy"), get(row, "vz"));
        assert_eq!(body.velocity, v, "{name}: row {row:?}");
        let omega = Vector::new(get(row, "wx"), get(row, "wy"), get(row, "wz"));
        let measured = body.angular_velocity();
        assert!(
            (measured - omega).norm() <= 1e-12 * omega.norm().max(1.0),
            "{name}: angular velocity {measured:?}, row {omega:?}, tolerance 1e-12 relative"
        );
        let turn = sim.input_orientation(i).angle_to(&q);
        assert!(
            turn <= 1e-12,
            "{name}: input orientation {turn} rad from the row's, tolerance 1e-12"
        );
    }
    assert_eq!(
        sim.tracked.len(),
        rows.len(),
        "track = true tracks every row"
    );
    // The same rows as [[body]] entries: the same world, bit for bit.
    let scene = std::fs::read_to_string(&path).unwrap();
    let twin =
        parse_scene(&as_body_entries(&scene, &rows), &path).expect("the [[body]] twin loads");
    assert_eq!(twin.world.names(), sim.world.names());
    assert_eq!(twin.world.bodies(), sim.world.bodies());
    assert_eq!(twin.frames, sim.frames);
    assert_eq!(twin.tracked, sim.tracked);
    assert_eq!(twin.time_step, sim.time_step);
}

/// Loads the example scene with its CSV replaced by `csv` (written next to a copy of the scene).
fn load_with(
    case: &str,
    csv: &str,
    extra: &str,
) -> (PathBuf, PathBuf, usize, Result<Simulation, SceneError>) {
    let dir = std::env::temp_dir().join(format!("polydem-body-file-shapes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv_path = dir.join(format!("{case}.csv"));
    std::fs::write(&csv_path, csv).unwrap();
    let scene = std::fs::read_to_string(example_path())
        .unwrap()
        .replace("polyhedra_from_file.csv", &format!("{case}.csv"))
        + extra;
    let path = dir.join(format!("{case}.toml"));
    let line = scene
        .lines()
        .position(|l| l.starts_with("path = "))
        .unwrap()
        + 1;
    let result = parse_scene(&scene, &path);
    (path, csv_path, line, result)
}

const GOOD: &str = "id,shape,x,y,z,qw,qx,qy,qz,vx,vy,vz\n1,cube,0.0,0.0,0.2,1.0,0.0,0.0,0.0,0.0,0.0,0.0\n2,wedge,0.2,0.0,0.2,0.5,0.5,0.5,0.5,0.0,0.0,-1.0\n";

#[test]
fn bad_rows_name_the_csv_file_line_and_column() {
    // (case, CSV, extra scene text, CSV line, column, a word the message must contain)
    let cases = [
        (
            "unknown_shape",
            GOOD.replace("2,wedge", "2,wegde"),
            "",
            3,
            "shape",
            "unknown shape 'wegde'",
        ),
        (
            "column_count",
            GOOD.replace("0.2,0.0,0.2,0.5", "0.2,0.0,0.5"),
            "",
            3,
            "row",
            "11 fields where the header has 12 columns",
        ),
        (
            "non_finite",
            GOOD.replace("0.0,0.0,-1.0", "0.0,inf,-1.0"),
            "",
            3,
            "vy",
            "finite",
        ),
        (
            "not_unit",
            GOOD.replace("0.5,0.5,0.5,0.5", "0.5,0.5,0.5,0.6"),
            "",
            3,
            "qw, qx, qy, qz",
            "within 1e-6 of 1",
        ),
        (
            "no_number",
            GOOD.replace("1,cube,0.0", "1,cube,zero"),
            "",
            2,
            "x",
            "not a number",
        ),
        (
            "missing_column",
            GOOD.replace(",qz,", ",q,"),
            "",
            1,
            "qz",
            "required: shape, x, y, z, qw, qx, qy, qz",
        ),
        (
            "half_spin",
            "shape,x,y,z,qw,qx,qy,qz,wx,wy\ncube,0,0,0.2,1,0,0,0,0,0\n".to_owned(),
            "",
            1,
            "wx",
            "give all three angular velocity columns wx, wy, wz or none",
        ),
    ];
    for (case, csv, extra, csv_line, column, word) in cases {
        let (path, csv_path, scene_line, result) = load_with(case, &csv, extra);
        let message = result
            .expect_err(&format!("{case}: {csv:?} accepted"))
            .to_string();
        let scene_location = format!("{}:{scene_line}: body_file[0].path: ", path.display());
        let csv_location = format!("{}:{csv_line}: {column}: ", csv_path.display());
        assert!(
            message.starts_with(&scene_location) && message.contains(&csv_location) && message.contains(word),
            "{case}: message {message:?} does not name {scene_location:?}, then {csv_location:?} and {word:?}"
        );
    }
}

#[test]
fn velocities_from_a_file_without_them_and_zeroed_velocities() {
    let csv = "shape,x,y,z,qw,qx,qy,qz\ncube,0.0,0.0,0.2,1.0,0.0,0.0,0.0\n";
    let extra = "velocities = \"file\"\n";
    let (path, csv_path, _, result) = load_with("no_velocities", csv, extra);
    let message = result
        .expect_err("velocities = \"file\" without columns accepted")
        .to_string();
    let line = std::fs::read_to_string(example_path())
        .unwrap()
        .lines()
        .count()
        + 1;
    let expected = format!(
        "{}:{line}: body_file[0].velocities: {} has no vx, vy, vz or wx, wy, wz columns",
        path.display(),
        csv_path.display()
    );
    assert_eq!(message, expected);
    let (_, _, _, result) = load_with("zeroed", GOOD, "velocities = \"zero\"\n");
    let sim = result.expect("velocities = \"zero\" loads");
    assert!(
        sim.world
            .bodies()
            .iter()
            .all(|b| b.velocity == Vector::zeros()),
        "velocities = \"zero\" left {:?}",
        sim.world
            .bodies()
            .iter()
            .map(|b| b.velocity)
            .collect::<Vec<_>>()
    );
    let (_, _, _, result) = load_with("from_file", GOOD, "");
    assert_eq!(
        result.expect("loads").world.bodies()[1].velocity,
        Vector::new(0.0, 0.0, -1.0)
    );
}

#[test]
fn a_shape_table_body_name_taken_twice_is_refused() {
    let csv = GOOD.replace("2,wedge", "1,wedge");
    let (path, _, _, result) = load_with("duplicate", &csv, "");
    let message = result.expect_err("duplicate id accepted").to_string();
    let line = std::fs::read_to_string(example_path())
        .unwrap()
        .lines()
        .position(|l| l.starts_with("name_prefix"))
        .unwrap()
        + 1;
    let expected = format!(
        "{}:{line}: body_file[0].name_prefix: duplicate body 'rock_1'",
        path.display()
    );
    assert!(
        message.starts_with(&expected),
        "message {message:?}, expected the start {expected:?}"
    );
}
