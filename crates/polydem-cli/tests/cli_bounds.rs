//! The command line refuses runs that would never end or outgrow the machine, at once and with the number
//! that explains why: `end_time = 1e300` (a step count beyond the counter), an `--end-time` far out
//! (beyond the step limit) and `polydem rockfill --size 12` (millions of rocks). A contact-pairs file that starts with a byte-order mark is answered.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn polydem(args: &[&str]) -> (Output, f64) {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args(args)
        .output()
        .expect("run polydem");
    (out, start.elapsed().as_secs_f64())
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem_cli_{tag}_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Fails unless the command failed within `seconds` with every part in its standard error.
fn assert_refused(args: &[&str], parts: &[&str], seconds: f64) {
    let (out, elapsed) = polydem(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && elapsed < seconds,
        "polydem {args:?}: expected a refusal within {seconds} s, got {} after {elapsed:.2} s: {stderr}",
        out.status
    );
    for part in parts {
        assert!(
            stderr.contains(part),
            "polydem {args:?}: the message names '{part}': {stderr}"
        );
    }
}

#[test]
fn runs_beyond_the_step_counter_or_the_limit_are_refused_at_once() {
    let dir = temp_dir("bounds");
    let scene_text = std::fs::read_to_string(repo().join("scenes/sphere_bounce.toml")).unwrap();
    let far = scene_text.replace("end_time = 0.6", "end_time = 1e300");
    assert_ne!(far, scene_text, "sphere_bounce.toml sets end_time = 0.6");
    let scene = dir.join("far.toml");
    std::fs::write(&scene, far).unwrap();
    let out = dir.join("out");
    let (scene, out) = (scene.to_str().unwrap(), out.to_str().unwrap());
    assert_refused(
        &["run", scene, "--out", out, "-q"],
        &["simulation.end_time", "step counter"],
        10.0,
    );
    let bounce = repo().join("scenes/sphere_bounce.toml");
    let bounce = bounce.to_str().unwrap();
    assert_refused(
        &["run", bounce, "--out", out, "-q", "--end-time", "1e4"],
        &["--end-time", "steps", "--max-steps"],
        10.0,
    );
    // The flag raises the limit of --end-time only.
    let (flag_alone, _) = polydem(&["run", bounce, "--out", out, "-q", "--max-steps", "10"]);
    assert!(
        !flag_alone.status.success(),
        "--max-steps without --end-time is refused"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_rockfill_sample_above_the_rock_limit_is_refused_before_generation() {
    let dir = temp_dir("rockfill_size");
    let out = dir.to_str().unwrap();
    assert_refused(
        &["rockfill", "--size", "12", "--out", out],
        &["rocks", "GB", "--max-rocks"],
        10.0,
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn contact_pairs_after_a_byte_order_mark_are_answered() {
    let dir = temp_dir("bom");
    let pair = r#"{"id":"p","a":[[0,0,0],[1,0,0],[0,1,0],[0,0,1]],"b":[[0.1,0.1,0.1],[2,0,0],[0,2,0],[0,0,2]]}"#;
    let file = dir.join("pairs.jsonl");
    std::fs::write(&file, format!("\u{feff}{pair}\n")).unwrap();
    let (out, _) = polydem(&["contact", file.to_str().unwrap()]);
    std::fs::remove_dir_all(&dir).ok();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let answer: serde_json::Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("one JSON answer expected: {e}: {stdout}"));
    assert_eq!(
        answer["status"], "overlap",
        "the pair after the mark is answered: {stdout}"
    );
}
