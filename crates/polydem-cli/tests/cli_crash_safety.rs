//! A run killed at any moment restarts into the straight run's outputs, byte for byte.
//!
//! `polydem run` flushes and syncs every series before each checkpoint it writes and replaces `.pvd`
//! collections whole, so after a `kill -9` the newest checkpoint has every row and frame up to its time on
//! disk; a restart from it into the same directory drops what came after and continues. Checked by killing
//! the settling box at a spread of moments (with CSV series, VTK frames, the contact network and
//! checkpoints on) and comparing every series with an uninterrupted run's. Also: a second run into a
//! directory another run is writing into is refused.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

fn out_dir(case: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem-cli-crash-{}-{case}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn scene() -> PathBuf {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/settling_box.toml"
    ))
    .to_owned()
}

fn command(args: &[OsString]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_polydem"));
    c.args(args).stdout(Stdio::null()).stderr(Stdio::piped());
    c
}

fn succeeds(args: &[OsString]) {
    let o = command(args).output().expect("polydem runs");
    assert!(
        o.status.success(),
        "polydem {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

const SERIES: [&str; 7] = [
    "bodies.csv",
    "energy.csv",
    "walls.csv",
    "contacts.csv",
    "polyhedra.pvd",
    "walls.pvd",
    "contacts.pvd",
];

#[test]
fn a_run_killed_at_any_moment_restarts_into_the_straight_runs_outputs() {
    let dir = out_dir("kill");
    let end = "0.8";
    let straight = dir.join("straight");
    let os = |s: &str| OsString::from(s);
    let plain = |out: &Path, interval: &str| -> Vec<OsString> {
        let mut a = vec![
            os("run"),
            scene().into(),
            os("--out"),
            out.into(),
            os("--end-time"),
            os(end),
        ];
        for flag in [
            "--vtk-interval",
            "--contacts-interval",
            "--checkpoint-interval",
        ] {
            a.extend([os(flag), os(interval)]);
        }
        a.push(os("--quiet"));
        a
    };
    // A first run finds the time of five CSV output intervals in whole steps; every output and every
    // checkpoint then falls on a CSV step, so a restart's first rows and frames are the straight run's.
    succeeds(&plain(&straight, "0.1"));
    let energy = read(&straight.join("energy.csv"));
    let interval = energy
        .lines()
        .nth(6)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .to_owned();
    let _ = std::fs::remove_dir_all(&straight);
    succeeds(&plain(&straight, &interval));
    let mut restarted = 0;
    for (k, delay_ms) in [15u64, 40, 80, 130, 200, 300, 450].into_iter().enumerate() {
        let killed = dir.join(format!("killed_{k}"));
        let mut child = command(&plain(&killed, &interval))
            .spawn()
            .expect("polydem starts");
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        let newest = std::fs::read_dir(killed.join("checkpoints"))
            .ok()
            .and_then(|entries| {
                entries
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.extension().is_some_and(|x| x == "pdck"))
                    .max()
            });
        let Some(newest) = newest else {
            continue; // killed before its first checkpoint: nothing to restart from
        };
        let mut again = plain(&killed, &interval);
        again.splice(1..2, [os("--restart"), newest.clone().into()]);
        succeeds(&again);
        for name in SERIES {
            let (a, b) = (read(&straight.join(name)), read(&killed.join(name)));
            assert!(
                a == b,
                "{name}: killed after {delay_ms} ms and restarted from {}, the series differs from the \
                 straight run's ({} against {} lines)",
                newest.display(),
                b.lines().count(),
                a.lines().count()
            );
        }
        restarted += 1;
    }
    assert!(
        restarted >= 3,
        "runs killed after a checkpoint and restarted: {restarted} of 7"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_second_run_into_a_directory_being_written_is_refused() {
    let dir = out_dir("lock");
    let os = |s: &str| OsString::from(s);
    let args = vec![
        os("run"),
        scene().into(),
        os("--out"),
        dir.clone().into(),
        os("--quiet"),
    ];
    let mut first = command(&args).spawn().expect("polydem starts");
    // Wait until the first run holds the directory (its series exist), then start the second.
    for _ in 0..200 {
        if dir.join("energy.csv").exists() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let second = command(&args).output().expect("polydem runs");
    let first_status = first.wait().expect("first run ends");
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert!(first_status.success(), "the first run failed");
    assert!(
        !second.status.success() && stderr.contains("another run is writing into"),
        "the second run into {}: status {:?}, stderr: {stderr}",
        dir.display(),
        second.status
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_restart_into_another_runs_directory_is_refused_and_leaves_it_as_it_was() {
    let dir = out_dir("splice");
    let os = |s: &str| OsString::from(s);
    let (first, second) = (dir.join("first"), dir.join("second"));
    let two = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/two_polyhedra_elastic.toml"
    ));
    for (scene, out) in [(scene(), &first), (two.to_owned(), &second)] {
        succeeds(&[
            os("run"),
            scene.into(),
            os("--out"),
            out.into(),
            os("--end-time"),
            os("0.05"),
            os("--checkpoint-interval"),
            os("0.02"),
            os("--quiet"),
        ]);
    }
    let checkpoint = std::fs::read_dir(first.join("checkpoints"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .min()
        .expect("checkpoints");
    let before = read(&second.join("bodies.csv"));
    let o = command(&[
        os("run"),
        os("--restart"),
        checkpoint.clone().into(),
        os("--out"),
        second.clone().into(),
        os("--quiet"),
    ])
    .output()
    .expect("polydem runs");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("holds the outputs of run"),
        "restart of {} into {}: status {:?}, stderr: {stderr}",
        checkpoint.display(),
        second.display(),
        o.status
    );
    assert_eq!(
        read(&second.join("bodies.csv")),
        before,
        "the refused restart rewrote bodies.csv"
    );
    // Into its own directory it continues.
    succeeds(&[
        os("run"),
        os("--restart"),
        checkpoint.into(),
        os("--out"),
        first.into(),
        os("--quiet"),
    ]);
    let _ = std::fs::remove_dir_all(&dir);
}
