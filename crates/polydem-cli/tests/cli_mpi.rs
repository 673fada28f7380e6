//! `mpirun -n P polydem run` (the feature `mpi`) writes what one process writes: `bodies.csv` byte for
//! byte, `walls.csv` byte for byte, checkpoints with the same state, VTK pieces whose data are the
//! one-process frame's; a checkpoint
//! written on P ranks continues on Q ranks (or without MPI) to the bits of an uninterrupted run; a rank that
//! fails stops every rank with its message.
//!
//! What is not bit for bit on P > 1 ranks (documented in `polydem_mpi`): the energy sums (the ledger, and
//! the elastic potential, the step's work terms and the external power of the last evaluation) are added
//! over the ranks' shares, grouped by part. `energy.csv` and those fields of the checkpoints are compared
//! within [`ENERGY_TOLERANCE`] of the largest magnitude among them; every other byte of a checkpoint's
//! state must be equal.
//!
//! Launched with `mpirun.mpich` (or `$POLYDEM_MPIRUN`), oversubscribed on a small machine with one rayon
//! thread per rank.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use polydem_mpi::launch;
use serde_json::Value;

const EXE: &str = env!("CARGO_BIN_EXE_polydem");

/// How far an energy sum added over the parts may be from one process's, relative to the largest
/// magnitude among the compared values: the same terms grouped differently, whose rounding differs by at
/// most about n ε of the sum of their magnitudes, with n up to ~10^4 terms per sum here (the contacts of
/// one evaluation) and ε = 1.1e-16.
const ENERGY_TOLERANCE: f64 = 1e-12;

fn scene(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes")).join(format!("{name}.toml"))
}

fn dir_of(case: &str) -> PathBuf {
    std::env::temp_dir().join(format!("polydem-cli-mpi-{}-{case}", std::process::id()))
}

/// The output directory of `case`, emptied.
fn out_dir(case: &str) -> PathBuf {
    let dir = dir_of(case);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// `polydem run ARGS` on `ranks` ranks (`None`: without `mpirun`); panics with the output on failure.
fn polydem(ranks: Option<usize>, args: &[&str]) -> Output {
    let mut command = match ranks {
        Some(n) => launch::command(n, EXE),
        None => Command::new(EXE),
    };
    let start = Instant::now();
    let output = command
        .env("RAYON_NUM_THREADS", "1")
        .arg("run")
        .args(args)
        .arg("--quiet")
        .output()
        .expect("polydem or mpirun starts");
    println!(
        "{ranks:?} ranks, {args:?}: {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(
        output.status.success(),
        "polydem run {args:?} on {ranks:?} ranks failed ({}): {}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Which of the lists a checkpoint holds are compared.
#[derive(Copy, Clone, Debug)]
enum Lists {
    /// The broad phase and every contact entry (a run one process steps with the general step).
    Whole,
    /// The touching contact entries only: one process runs a scene of spheres on the flat sphere layout,
    /// whose checkpoint holds no broad phase, an entry for each pair of the layout's own lists and an
    /// unsized sleeping state.
    Touching,
}

/// The state of a checkpoint as JSON, with the fields that are not the whole world's on several ranks
/// taken out (returned apart).
fn checkpoint_state(path: &Path, lists: Lists) -> (Value, Value) {
    let payload =
        polydem::io::checkpoint::load(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let store = payload.simulation.world.contacts();
    let touching: Vec<_> = store
        .keys()
        .iter()
        .zip(store.states())
        .filter(|(_, state)| state.is_active())
        .collect();
    let touching = serde_json::to_value(&touching).expect("contacts serialise");
    let mut sim = serde_json::to_value(&payload.simulation).expect("a simulation serialises");
    let world = sim["world"].as_object_mut().expect("world");
    if let Lists::Touching = lists {
        // The flat layout also leaves the sleeping state unsized (sleeping is off on several ranks).
        world.remove("sleep").expect("sleep");
        world.remove("broad_phase").expect("broad_phase");
        world.insert("contacts".into(), touching);
    }
    let ledger = world.remove("ledger").expect("ledger");
    let loads = world["loads"].as_object_mut().expect("loads");
    let mut sums = serde_json::Map::new();
    for key in [
        "elastic_potential",
        "damping_work",
        "friction_dissipation",
        "tangential_stiffness_work",
        "external_power",
    ] {
        sums.insert(key.into(), loads.remove(key).expect(key));
    }
    sums.insert("ledger".into(), ledger);
    (sim, Value::Object(sums))
}

fn assert_same_state(case: &str, got: &Path, expected: &Path, lists: Lists) {
    let (state, sums) = checkpoint_state(got, lists);
    let (expected_state, expected_sums) = checkpoint_state(expected, lists);
    if state != expected_state {
        let (a, b) = (state.to_string(), expected_state.to_string());
        let at = a
            .bytes()
            .zip(b.bytes())
            .position(|(x, y)| x != y)
            .unwrap_or(0);
        let context = |s: &str| s[at.saturating_sub(120)..(at + 120).min(s.len())].to_owned();
        panic!(
            "{case}: checkpoint {} differs from {} at JSON byte {at}: …{}… against …{}…",
            got.display(),
            expected.display(),
            context(&a),
            context(&b)
        );
    }
    let (got_sums, expected_sums) = (numbers(&sums), numbers(&expected_sums));
    let worst = assert_close(case, &got_sums, &expected_sums, &got.display().to_string());
    println!(
        "{case}: {} has the state of {}, and its energy sums within {worst:.1e} of their scale",
        got.display(),
        expected.display()
    );
}

/// The numbers of a JSON value, in document order (an absent initial total as NaN).
fn numbers(value: &Value) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    let mut walk = vec![(String::new(), value)];
    while let Some((path, v)) = walk.pop() {
        match v {
            Value::Object(map) => {
                walk.extend(map.iter().rev().map(|(k, v)| (format!("{path}/{k}"), v)))
            }
            Value::Number(n) => out.push((path, n.as_f64().expect("a number"))),
            Value::Null => out.push((path, f64::NAN)),
            other => panic!("{path}: not a number: {other}"),
        }
    }
    out
}

/// Asserts that `got` and `expected` (named values) agree within [`ENERGY_TOLERANCE`] of the largest
/// magnitude among `expected`; returns the largest difference relative to that scale.
fn assert_close(case: &str, got: &[(String, f64)], expected: &[(String, f64)], what: &str) -> f64 {
    assert_eq!(
        got.len(),
        expected.len(),
        "{case}: {what}: {got:?} against {expected:?}"
    );
    let scale = expected
        .iter()
        .map(|(_, v)| v.abs())
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for ((name, a), (other, b)) in got.iter().zip(expected) {
        assert_eq!(name, other, "{case}: {what}: fields differ");
        if a.is_nan() && b.is_nan() {
            continue;
        }
        let relative = (a - b).abs() / scale;
        assert!(
            relative <= ENERGY_TOLERANCE,
            "{case}: {what}: {name} = {a:e} against {b:e} one process wrote: {relative:.2e} of the scale \
             {scale:e} (tolerance {ENERGY_TOLERANCE:e})"
        );
        worst = worst.max(relative);
    }
    worst
}

/// `energy.csv` of `got` against `expected`'s: the same times, every term within [`ENERGY_TOLERANCE`] of
/// the row's largest magnitude.
fn assert_same_energy(case: &str, got: &Path, expected: &Path) {
    let rows = |dir: &Path| -> Vec<Vec<(String, f64)>> {
        let text = String::from_utf8(read(&dir.join("energy.csv"))).expect("UTF-8");
        let mut lines = text.lines();
        let header: Vec<String> = lines
            .next()
            .expect("a header")
            .split(',')
            .map(String::from)
            .collect();
        let parse = |line: &str| -> Vec<(String, f64)> {
            let values = line.split(',').map(|v| v.parse::<f64>().expect("a number"));
            header.iter().cloned().zip(values).collect()
        };
        lines.map(parse).collect()
    };
    let (mine, theirs) = (rows(got), rows(expected));
    assert_eq!(mine.len(), theirs.len(), "{case}: rows of energy.csv");
    let mut worst: f64 = 0.0;
    for (k, (a, b)) in mine.iter().zip(&theirs).enumerate() {
        assert_eq!(a[0], b[0], "{case}: energy.csv row {} time", k + 1);
        let row = format!("{}/energy.csv row {}", got.display(), k + 1);
        worst = worst.max(assert_close(case, a, b, &row));
    }
    println!("{case}: energy.csv within {worst:.1e} of each row's scale");
}

/// Per body, the values of every point and cell array of the `.vtu` files `files` (ASCII), keyed by
/// section, array and body; the cells' connectivity is left out (piece-local numbering).
fn vtk_by_body(files: &[PathBuf]) -> BTreeMap<(String, String, i64), Vec<String>> {
    let mut all = BTreeMap::new();
    for file in files {
        let text = String::from_utf8(read(file)).expect("ASCII VTK");
        let arrays = vtk_arrays(&text);
        for ((section, name), (components, values)) in &arrays {
            let owner = match section.as_str() {
                "Points" | "PointData" => "PointData",
                "CellData" => "CellData",
                _ => continue,
            };
            let bodies = &arrays[&(owner.to_owned(), "body".to_owned())].1;
            for (k, body) in bodies.iter().enumerate() {
                let body: i64 = body.parse().expect("a body index");
                let chunk = &values[k * components..(k + 1) * components];
                let entry = all.entry((section.clone(), name.clone(), body));
                entry.or_insert_with(Vec::new).extend(chunk.iter().cloned());
            }
        }
    }
    all
}

type Arrays = BTreeMap<(String, String), (usize, Vec<String>)>;

fn vtk_arrays(text: &str) -> Arrays {
    let attribute = |line: &str, name: &str| -> String {
        let start = line.find(&format!("{name}=\"")).expect(name) + name.len() + 2;
        line[start..start + line[start..].find('"').expect("closing quote")].to_owned()
    };
    let (mut arrays, mut section, mut current) = (Arrays::new(), String::new(), None);
    for line in text.lines().map(str::trim) {
        if let Some(s) = ["Points", "Cells", "PointData", "CellData"]
            .into_iter()
            .find(|s| line.starts_with(&format!("<{s}")))
        {
            section = s.to_owned();
        } else if line.starts_with("<DataArray") {
            let components = attribute(line, "NumberOfComponents")
                .parse()
                .expect("count");
            current = Some((attribute(line, "Name"), components, Vec::new()));
        } else if line.starts_with("</DataArray") {
            let (name, components, values) = current.take().expect("an open array");
            arrays.insert((section.clone(), name), (components, values));
        } else if let Some((_, _, values)) = current.as_mut() {
            values.extend(line.split_whitespace().map(str::to_owned));
        }
    }
    arrays
}

/// Compares every frame of series `kind` of `got` (pieces listed in `.pvtu` files) with `expected`'s
/// one-process `.vtu` frames, body by body.
fn assert_same_frames(case: &str, kind: &str, got: &Path, expected: &Path) {
    let mut frames = 0;
    for entry in std::fs::read_dir(expected.join("vtk")).expect("vtk directory") {
        let path = entry.expect("an entry").path();
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .expect("a name")
            .to_owned();
        let Some(stem) = name
            .strip_prefix(&format!("{kind}_"))
            .and_then(|s| s.strip_suffix(".vtu"))
        else {
            continue;
        };
        let pvtu =
            String::from_utf8(read(&got.join(format!("vtk/{kind}_{stem}.pvtu")))).expect("text");
        let pieces: Vec<PathBuf> = pvtu
            .lines()
            .filter_map(|l| l.trim().strip_prefix("<Piece Source=\""))
            .map(|l| got.join("vtk").join(&l[..l.find('"').expect("quote")]))
            .collect();
        let (a, b) = (
            vtk_by_body(&pieces),
            vtk_by_body(std::slice::from_ref(&path)),
        );
        assert!(!b.is_empty(), "{case}: {} has no body data", path.display());
        if a != b {
            let first = b
                .iter()
                .find(|(k, v)| a.get(*k) != Some(*v))
                .map(|(k, _)| k.clone());
            panic!(
                "{case}: the pieces of {kind} at step {stem} differ from {}: first at {first:?}: {:?} against {:?}",
                path.display(),
                first.as_ref().and_then(|k| a.get(k)),
                first.as_ref().and_then(|k| b.get(k))
            );
        }
        frames += 1;
    }
    assert!(
        frames > 0,
        "{case}: no {kind} frames in {}",
        expected.display()
    );
    println!("{case}: {frames} {kind} frames of pieces equal, body by body, to one process's");
}

fn checkpoints(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("checkpoints"))
        .expect("checkpoints")
        .map(|e| e.expect("entry").path())
        .collect();
    files.sort();
    files
}

fn assert_same_run(case: &str, got: &Path, expected: &Path, kinds: &[&str], lists: Lists) {
    for series in ["bodies.csv", "walls.csv"] {
        assert!(
            read(&got.join(series)) == read(&expected.join(series)),
            "{case}: {}/{series} differs from {}/{series}",
            got.display(),
            expected.display()
        );
    }
    let (mine, theirs) = (checkpoints(got), checkpoints(expected));
    assert_eq!(
        mine.len(),
        theirs.len(),
        "{case}: checkpoints {mine:?} against {theirs:?}"
    );
    for (a, b) in mine.iter().zip(&theirs) {
        assert_same_state(case, a, b, lists);
    }
    for kind in kinds {
        assert_same_frames(case, kind, got, expected);
    }
    assert_same_energy(case, got, expected);
}

/// How a compared run starts: a scene file, or a checkpoint.
#[derive(Copy, Clone)]
enum Start<'a> {
    Scene(&'a str),
    Checkpoint(&'a Path),
}

/// `polydem run` of `start` into `out` on `ranks` ranks with `args`.
fn run_from(ranks: Option<usize>, start: Start, out: &Path, args: &[&str]) {
    let (source, out) = match start {
        Start::Scene(name) => (scene(name).display().to_string(), out.display().to_string()),
        Start::Checkpoint(file) => (file.display().to_string(), out.display().to_string()),
    };
    let mut all: Vec<&str> = match start {
        Start::Scene(_) => vec![&source],
        Start::Checkpoint(_) => vec!["--restart", &source],
    };
    all.extend(["--out", &out]);
    all.extend_from_slice(args);
    polydem(ranks, &all);
}

/// Runs `start` without MPI and on each of `ranks`, comparing each with the run without MPI; then
/// continues the first checkpoint across rank counts (2 → 3, 3 → none, none → 2) and compares the last
/// checkpoint with the uninterrupted run's.
fn runs_and_restarts(
    name: &str,
    start: Start,
    args: &[&str],
    ranks: &[usize],
    kinds: &[&str],
    lists: Lists,
) {
    let one = out_dir(&format!("{name}_one"));
    run_from(None, start, &one, args);
    for &p in ranks {
        let out = out_dir(&format!("{name}_{p}"));
        run_from(Some(p), start, &out, args);
        assert_same_run(&format!("{name} on {p} ranks"), &out, &one, kinds, lists);
    }
    let last = |dir: &Path| checkpoints(dir).last().cloned().expect("a checkpoint");
    let interval = args[args
        .iter()
        .position(|a| *a == "--checkpoint-interval")
        .expect("checkpoints")
        + 1];
    for (from, to) in [(Some(2), Some(3)), (Some(3), None), (None, Some(2))] {
        let source = match from {
            Some(p) => dir_of(&format!("{name}_{p}")),
            None => one.clone(),
        };
        let checkpoint = checkpoints(&source)[0].clone();
        let out = out_dir(&format!("{name}_restart_{from:?}_{to:?}"));
        run_from(
            to,
            Start::Checkpoint(&checkpoint),
            &out,
            &["--checkpoint-interval", interval],
        );
        let case = format!(
            "{name} saved on {from:?} ranks at {}, continued on {to:?}",
            checkpoint.display()
        );
        assert_same_state(&case, &last(&out), &last(&one), lists);
    }
}

#[test]
fn spheres_on_several_ranks_write_what_one_process_writes_and_restart_on_any_rank_count() {
    // Sphere bed a: 3000 spheres resting in contact (tangential springs), 100 steps, checkpoints at 50
    // and 100.
    let args = [
        "--end-time",
        "2e-4",
        "--checkpoint-interval",
        "1e-4",
        "--vtk-interval",
        "1e-4",
        "--vtk-ascii",
    ];
    let start = Start::Scene("sphere_bed_a_hertz_5ms");
    runs_and_restarts(
        "bed",
        start,
        &args,
        &[2, 3, 4],
        &["spheres"],
        Lists::Touching,
    );
}

#[test]
fn polyhedra_and_spheres_on_several_ranks_write_what_one_process_writes_and_restart_on_any_rank_count(
) {
    // Spheres and polyhedra settling into a pile in a box: every kind of contact of the general step is
    // present from about 0.15 s. One process runs to 0.16 s (6721 steps); from its checkpoint the compared
    // runs continue (a restored world cut on P ranks).
    let pile = out_dir("pile_start");
    run_from(
        None,
        Start::Scene("mixed_spheres_polyhedra"),
        &pile,
        &["--end-time", "0.16", "--checkpoint-interval", "0.16"],
    );
    let checkpoint = checkpoints(&pile)
        .last()
        .cloned()
        .expect("the checkpoint at 0.16 s");
    // About 100 steps of 23.8 µs, checkpoints and frames about every 50.
    let args = [
        "--end-time",
        "0.1624",
        "--checkpoint-interval",
        "1.2e-3",
        "--vtk-interval",
        "1.2e-3",
        "--vtk-ascii",
    ];
    let kinds = ["spheres", "polyhedra"];
    runs_and_restarts(
        "pile",
        Start::Checkpoint(&checkpoint),
        &args,
        &[2, 3, 4],
        &kinds,
        Lists::Whole,
    );
    // The settling box: polyhedra falling in a box of walls, 160 steps.
    let args = [
        "--end-time",
        "6.4e-3",
        "--checkpoint-interval",
        "3.2e-3",
        "--vtk-interval",
        "3.2e-3",
        "--vtk-ascii",
    ];
    let one = out_dir("box_one");
    run_from(None, Start::Scene("settling_box"), &one, &args);
    for ranks in [2, 3] {
        let out = out_dir(&format!("box_{ranks}"));
        run_from(Some(ranks), Start::Scene("settling_box"), &out, &args);
        let case = format!("settling box on {ranks} ranks");
        assert_same_run(&case, &out, &one, &["polyhedra"], Lists::Whole);
    }
}

#[test]
fn a_rank_that_fails_stops_every_rank_with_its_message() {
    // An output directory under a regular file cannot be created: rank 0 fails, the others wait in the
    // first collective until the abort stops them.
    let blocker = out_dir("blocker");
    std::fs::write(&blocker, "a file").expect("a file in the temporary directory");
    let out = blocker.join("out");
    let start = Instant::now();
    let output = launch::command(3, EXE)
        .arg("run")
        .arg(scene("settling_box"))
        .arg("--out")
        .arg(&out)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("mpirun starts");
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success(),
        "mpirun succeeded with {}: {stderr}",
        out.display()
    );
    assert!(
        stderr.contains("rank 0: error: cannot create output directory"),
        "the failing rank's message is missing ({}): {stderr}; stdout: {}",
        output.status,
        String::from_utf8_lossy(&output.stdout)
    );
    assert!(
        elapsed < Duration::from_secs(30),
        "the ranks stopped after {elapsed:?} (limit 30 s)"
    );
    println!(
        "a failing rank stopped the run in {:.1} s: {}",
        elapsed.as_secs_f64(),
        stderr.trim()
    );
}
