//! The `polydem contact` command line, run as a built binary: answers in input order, an error record for a
//! malformed line in the middle (the lines after it still answered), blank lines skipped, standard input
//! via `-`, and `--out`.
//!
//! The pairs are axis-aligned boxes whose contact features have closed forms: two boxes apart along x by
//! a gap g are separated with distance g and normal +x; overlapping by p along x (less than along y, z) they
//! overlap with depth p and normal +x.

use std::io::Write;
use std::process::{Command, Stdio};

use serde_json::Value;

fn box_points(mins: [f64; 3], maxs: [f64; 3]) -> String {
    let mut corners = Vec::new();
    for x in [mins[0], maxs[0]] {
        for y in [mins[1], maxs[1]] {
            for z in [mins[2], maxs[2]] {
                corners.push(format!("[{x},{y},{z}]"));
            }
        }
    }
    format!("[{}]", corners.join(","))
}

/// Four lines: separated boxes (gap `gap`), a malformed line, an empty line, overlapping boxes (`pen`).
fn input(gap: f64, pen: f64) -> String {
    let a = box_points([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]);
    let separated = box_points([1.0 + gap, -0.5, -0.5], [3.0, 0.5, 0.5]);
    let overlapping = box_points([1.0 - pen, -0.5, -0.5], [3.0, 0.5, 0.5]);
    format!(
        "{{\"id\": \"apart\", \"a\": {a}, \"b\": {separated}}}\n\
         {{\"id\": \"broken\", \"a\": {a}, \"b\": [[0,0,0],[1,0,0]]}}\n\
         \n\
         {{\"id\": {{\"k\": 4}}, \"a\": {a}, \"b\": {overlapping}}}\n"
    )
}

fn parse(stdout: &[u8]) -> Vec<Value> {
    String::from_utf8(stdout.to_vec())
        .expect("utf-8 output")
        .lines()
        .map(|l| {
            serde_json::from_str(l).unwrap_or_else(|e| panic!("output line {l} is not JSON: {e}"))
        })
        .collect()
}

fn number(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("`{key}` is not a number in {v}"))
}

fn vector(v: &Value, key: &str) -> [f64; 3] {
    let a = v[key]
        .as_array()
        .unwrap_or_else(|| panic!("`{key}` is not an array in {v}"));
    [
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    ]
}

fn check_answers(lines: &[Value], gap: f64, pen: f64) {
    // Scale of the pair: box a has a diagonal of 2√3; tolerances are relative to it.
    let tol = 1e-12 * 2.0 * 3f64.sqrt();
    assert_eq!(
        lines.len(),
        3,
        "one output per non-blank input line: {lines:?}"
    );

    let apart = &lines[0];
    assert_eq!(apart["id"], "apart");
    assert_eq!(apart["status"], "separated", "{apart}");
    let d = number(apart, "distance");
    assert!(
        (d - gap).abs() <= tol,
        "distance: measured {d}, expected {gap}, tolerance {tol:e}"
    );
    assert_eq!(
        number(apart, "depth"),
        0.0,
        "depth of a separated pair: {apart}"
    );
    let n = vector(apart, "normal");
    assert!(
        (n[0] - 1.0).abs() <= tol && n[1].abs() <= tol && n[2].abs() <= tol,
        "normal {n:?}, expected [1,0,0]"
    );

    let broken = &lines[1];
    assert_eq!(broken["id"], "broken");
    assert_eq!(
        broken["line"], 2,
        "error record names the input line: {broken}"
    );
    assert!(
        broken["error"].as_str().unwrap().contains("too few points"),
        "{broken}"
    );

    let overlap = &lines[2];
    assert_eq!(overlap["id"], serde_json::json!({"k": 4}));
    assert_eq!(overlap["status"], "overlap", "{overlap}");
    let depth = number(overlap, "depth");
    assert!(
        (depth - pen).abs() <= tol,
        "depth: measured {depth}, expected {pen}, tolerance {tol:e}"
    );
    let n = vector(overlap, "normal");
    assert!(
        (n[0] - 1.0).abs() <= tol && n[1].abs() <= tol && n[2].abs() <= tol,
        "normal {n:?}, expected [1,0,0]"
    );
    let (c1, c2, cm) = (
        vector(overlap, "point_a"),
        vector(overlap, "point_b"),
        vector(overlap, "point"),
    );
    assert!(
        (c1[0] - 1.0).abs() <= tol,
        "c1 {c1:?} must lie on a's face x = 1"
    );
    assert!(
        (c2[0] - (1.0 - pen)).abs() <= tol,
        "c2 {c2:?} must lie on b's face x = 1 - {pen}"
    );
    for k in 0..3 {
        assert!(
            (cm[k] - 0.5 * (c1[k] + c2[k])).abs() <= tol,
            "c_M {cm:?} is not the midpoint of {c1:?} and {c2:?}"
        );
    }
}

#[test]
fn contact_answers_a_file_in_order_with_an_error_record_in_the_middle() {
    let (gap, pen) = (0.25, 0.125);
    let dir = std::env::temp_dir().join(format!("polydem-cli-contact-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pairs.jsonl");
    std::fs::write(&path, input(gap, pen)).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .arg("contact")
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "exit status {:?}, stderr {}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    check_answers(&parse(&output.stdout), gap, pen);

    let out_path = dir.join("answers.jsonl");
    let output = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .arg("contact")
        .arg(&path)
        .arg("--out")
        .arg(&out_path)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "--out run failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        output.stdout.is_empty(),
        "with --out nothing goes to stdout"
    );
    check_answers(&parse(&std::fs::read(&out_path).unwrap()), gap, pen);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn contact_reads_standard_input_with_dash() {
    let (gap, pen) = (1e-3, 0.3);
    let mut child = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args(["contact", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input(gap, pen).as_bytes())
        .unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(
        output.status.success(),
        "stderr {}",
        String::from_utf8_lossy(&output.stderr)
    );
    check_answers(&parse(&output.stdout), gap, pen);
}

#[test]
fn contact_fails_cleanly_on_a_missing_file() {
    let output = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args(["contact", "/this/path/does/not/exist.jsonl"])
        .env("RUST_BACKTRACE", "0")
        .env("RUST_LIB_BACKTRACE", "0")
        .output()
        .unwrap();
    assert!(
        !output.status.success(),
        "a missing input file must be a failure"
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("cannot open pairs file"),
        "stderr: {stderr}"
    );
}

/// A program driving `polydem contact -` over pipes gets each answer as soon as it sends the pair, before
/// it closes standard input (answers are not held in a block buffer when standard output is not a file).
#[test]
fn contact_on_a_pipe_answers_each_line_before_the_input_ends() {
    use std::io::BufRead;
    let mut child = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args(["contact", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("polydem starts");
    let mut stdin = child.stdin.take().unwrap();
    let first_line = input(0.1, 0.2).lines().next().unwrap().to_owned();
    writeln!(stdin, "{first_line}").unwrap();
    stdin.flush().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = std::io::BufReader::new(stdout).read_line(&mut line);
        let _ = tx.send(line);
    });
    let answer = rx.recv_timeout(std::time::Duration::from_secs(20));
    drop(stdin);
    let _ = child.wait();
    let answer = answer.expect("no answer within 20 s while standard input stayed open");
    assert!(answer.contains("\"apart\""), "answer: {answer}");
}
