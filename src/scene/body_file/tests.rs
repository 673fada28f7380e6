//! Unit tests of both tables: columns by name, comments, and errors naming the file, line and column.

use super::*;
use crate::math::Real;

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem-body-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn reads_columns_by_name_and_skips_comments() {
    let path = write(
        "ok.csv",
        "# provenance\n# more\nradius,z,y,x,id,extra\n0.002,0.3,0.2,0.1,7,foo\n# mid comment\n0.001,0.6,0.5,0.4,9,bar\n",
    );
    let rows = read_sphere_table(&path).unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0].id, "7");
    assert_eq!(rows[0].position, Vector::new(0.1, 0.2, 0.3));
    assert_eq!(rows[1].radius, 0.001);
    assert_eq!(rows[1].velocity, None);
}

#[test]
fn a_bad_number_names_file_line_and_column() {
    let path = write(
        "bad.csv",
        "# header comment\nx,y,z,radius,vx,vy,vz\n0,0,0,0.001,0,0,0\n0,0,abc,0.001,0,0,0\n",
    );
    let message = read_sphere_table(&path).unwrap_err().to_string();
    let expected = format!("{}:4: z:", path.display());
    assert!(
        message.starts_with(&expected),
        "message {message:?} does not start with {expected:?}"
    );
    let path = write("neg.csv", "x,y,z,radius\n0,0,0,-1\n");
    let message = read_sphere_table(&path).unwrap_err().to_string();
    assert!(
        message.contains("neg.csv:2: radius:"),
        "message {message:?} does not name line 2, column radius"
    );
    let path = write("nocol.csv", "x,y,radius\n0,0,1\n");
    let message = read_sphere_table(&path).unwrap_err().to_string();
    assert!(message.contains("nocol.csv:1: z:"), "{message}");
}

/// The message starts with `FILE:LINE: COLUMN:`.
fn assert_location(message: &str, path: &Path, line: u64, column: &str) {
    let expected = format!("{}:{line}: {column}:", path.display());
    assert!(
        message.starts_with(&expected),
        "message {message:?} does not start with {expected:?}"
    );
}

const POSES: &str = "# two rocks\nid,shape,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\na,rock,0.1,0.2,0.3,1,0,0,0,0,0,-1,0,0,0\nb,cube,0.4,0.5,0.6,0.7071067811865476,0,0.7071067811865476,0,1,2,3,4,5,6\n";

#[test]
fn reads_a_shape_table_with_its_poses_and_velocities() {
    let path = write("poses.csv", POSES);
    let BodyTable::Poses(rows) = read_body_table(&path).unwrap() else {
        panic!("{POSES:?} read as a sphere table")
    };
    assert_eq!(rows.len(), 2);
    assert_eq!((rows[0].id.as_str(), rows[0].shape.as_str()), ("a", "rock"));
    assert_eq!(rows[1].line, 4);
    assert_eq!(rows[1].position, Vector::new(0.4, 0.5, 0.6));
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let expected = Rotation::from_quaternion(nalgebra::Quaternion::new(h, 0.0, h, 0.0));
    assert_eq!(rows[1].orientation, expected);
    assert_eq!(rows[0].velocity, Some(Vector::new(0.0, 0.0, -1.0)));
    assert_eq!(rows[1].angular_velocity, Some(Vector::new(4.0, 5.0, 6.0)));
    // Without the optional columns: row numbers as ids, no velocities.
    let path = write(
        "poses_min.csv",
        "qz,qy,qx,qw,z,y,x,shape\n0,0,0,1,3,2,1,rock\n",
    );
    let BodyTable::Poses(rows) = read_body_table(&path).unwrap() else {
        panic!("read as a sphere table")
    };
    assert_eq!(rows[0].id, "1");
    assert_eq!(rows[0].position, Vector::new(1.0, 2.0, 3.0));
    assert_eq!((rows[0].velocity, rows[0].angular_velocity), (None, None));
}

/// Within the tolerance the quaternion is normalised; beyond it the row is refused, naming the columns.
#[test]
fn a_quaternion_is_normalised_within_the_tolerance_and_refused_beyond() {
    let row = |w: Real| format!("shape,x,y,z,qw,qx,qy,qz\nrock,0,0,0,{w},0,0,0\n");
    let inside = 1.0 + 0.5 * QUATERNION_NORM_TOLERANCE;
    let path = write("q_inside.csv", &row(inside));
    let BodyTable::Poses(rows) = read_body_table(&path).unwrap() else {
        panic!("read as a sphere table")
    };
    let norm = rows[0].orientation.quaternion().norm();
    assert!(
        (norm - 1.0).abs() <= 4.0 * Real::EPSILON,
        "qw = {inside}: normalised norm {norm}, expected 1 within 4 ε"
    );
    let outside = 1.0 + 2.0 * QUATERNION_NORM_TOLERANCE;
    let path = write("q_outside.csv", &row(outside));
    let message = read_body_table(&path).unwrap_err().to_string();
    assert_location(&message, &path, 2, "qw, qx, qy, qz");
    assert!(message.contains("1e-6"), "{message}");
}

#[test]
fn shape_table_errors_name_the_line_and_column() {
    // (case, text, line, column)
    let cases = [
        ("count", POSES.replace("0.4,0.5,0.6,", "0.4,0.5,"), 4, "row"),
        (
            "nan",
            POSES.replace("0.1,0.2,0.3,1,0,0", "0.1,0.2,0.3,1,nan,0"),
            3,
            "qx",
        ),
        ("inf", POSES.replace(",4,5,6", ",4,inf,6"), 4, "wy"),
        ("text", POSES.replace("0.4,0.5", "0.4,five"), 4, "y"),
        ("no_qz", POSES.replace(",qz,", ",q_z,"), 2, "qz"),
        ("two_w", POSES.replace(",wz", ",w_z"), 2, "wx"),
        (
            "radius",
            "shape,radius,x\nrock,1,0\n".to_owned(),
            1,
            "shape",
        ),
        ("empty_shape", POSES.replace("a,rock", "a,"), 3, "shape"),
        (
            "no_rows",
            "shape,x,y,z,qw,qx,qy,qz\n# nothing\n".to_owned(),
            1,
            "row",
        ),
    ];
    for (case, text, line, column) in cases {
        let path = write(&format!("poses_{case}.csv"), &text);
        let message = read_body_table(&path)
            .expect_err(&format!("{case}: {text:?} accepted"))
            .to_string();
        assert_location(&message, &path, line, column);
    }
}

#[test]
fn a_sphere_row_with_the_wrong_field_count_names_its_line() {
    let path = write("count.csv", "x,y,z,radius\n0,0,0,0.001\n1,1,0.001\n");
    let message = read_sphere_table(&path).unwrap_err().to_string();
    assert_location(&message, &path, 3, "row");
    assert!(
        message.contains("3 fields where the header has 4 columns"),
        "{message}"
    );
}
