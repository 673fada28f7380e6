//! `polydem run --contacts-interval T`: the contact network (`contacts.csv`, VTK lines in `contacts.pvd`).
//!
//! Checked against the run's other outputs rather than against itself: the wall rows of each output time
//! sum to the force `walls.csv` reports on that wall (to rounding of the sum's order), every frame holds one
//! line per CSV row of its time, normals are unit and depths positive; a restart into the same directory
//! continues the network to the straight run's bytes; the flat sphere layout writes the same network as
//! the general step.

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;

/// 200 steps of sphere bed a with the network every 50 steps.
const BED_RUN: [&str; 5] = [
    "run",
    "--end-time",
    "0.0004",
    "--contacts-interval",
    "0.0001",
];

fn out_dir(case: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "polydem-cli-contacts-{}-{case}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn scene_path(name: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("scenes")
        .join(name)
}

fn run(args: &[&str], paths: &[(&str, &Path)]) {
    let mut all: Vec<OsString> = args.iter().map(OsString::from).collect();
    for (flag, path) in paths {
        if !flag.is_empty() {
            all.push(flag.into());
        }
        all.push(path.as_os_str().to_owned());
    }
    all.push("--quiet".into());
    let o = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args(&all)
        .output()
        .expect("polydem runs");
    assert!(
        o.status.success(),
        "polydem {all:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The rows of a CSV file as fields, header checked.
fn rows(path: &Path, header: &str) -> Vec<Vec<String>> {
    let text = read(path);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(header), "{}", path.display());
    lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect()
}

fn num(field: &str) -> f64 {
    field.parse().unwrap_or_else(|e| panic!("{field:?}: {e}"))
}

#[test]
fn the_contact_network_sums_to_the_wall_forces_and_each_frame_draws_its_rows() {
    let out = out_dir("bed");
    let scene = scene_path("sphere_bed_a_hertz_5ms.toml");
    run(&BED_RUN, &[("", &scene), ("--out", &out)]);
    let contacts = rows(
        &out.join("contacts.csv"),
        "t,kind,a,b,px,py,pz,nx,ny,nz,depth,fx,fy,fz",
    );
    // (time, wall) -> sum of the force on the wall, and of its magnitude (for the rounding bound).
    let mut on_walls: BTreeMap<(String, String), ([f64; 3], f64)> = BTreeMap::new();
    let mut per_time: BTreeMap<String, usize> = BTreeMap::new();
    for r in &contacts {
        let n = [num(&r[7]), num(&r[8]), num(&r[9])];
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((norm - 1.0).abs() < 1e-12, "row {r:?}: |n| = {norm}");
        assert!(
            num(&r[10]) > 0.0,
            "row {r:?}: an active contact has a positive depth"
        );
        *per_time.entry(r[0].clone()).or_default() += 1;
        if r[1] == "wall" {
            let f = [num(&r[11]), num(&r[12]), num(&r[13])];
            let e = on_walls.entry((r[0].clone(), r[2].clone())).or_default();
            for (sum, fk) in e.0.iter_mut().zip(f) {
                *sum -= fk;
            }
            e.1 += (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        }
    }
    assert!(
        per_time.len() >= 4,
        "output times with contacts: {per_time:?}"
    );
    let mut compared = 0;
    for r in rows(&out.join("walls.csv"), "t,wall,fx,fy,fz") {
        let Some((sum, scale)) = on_walls.get(&(r[0].clone(), r[1].clone())) else {
            continue;
        };
        for k in 0..3 {
            let reported = num(&r[2 + k]);
            let tolerance = 1e-12 * scale;
            assert!(
                (sum[k] - reported).abs() <= tolerance,
                "t = {}, wall {}, component {k}: contacts sum to {} N, walls.csv has {reported} N \
                 (tolerance {tolerance:e} N)",
                r[0],
                r[1],
                sum[k]
            );
        }
        compared += 1;
    }
    assert!(compared >= 4, "wall rows compared: {compared}");
    let pvd = read(&out.join("contacts.pvd"));
    assert_eq!(
        pvd.matches("<DataSet").count(),
        5,
        "frames at 0, 0.1, …, 0.4 ms: {pvd}"
    );
    for line in pvd.lines().filter(|l| l.contains("<DataSet")) {
        let file = line
            .split("file=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .unwrap();
        let t: f64 = num(line
            .split("timestep=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .unwrap());
        let vtp = read(&out.join(file));
        let expected = per_time
            .iter()
            .find(|(time, _)| num(time) == t)
            .map_or(0, |(_, n)| *n);
        assert!(
            vtp.contains(&format!("NumberOfLines=\"{expected}\"")),
            "{file} at t = {t}: expected {expected} lines"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_restart_into_the_same_directory_continues_the_contact_network() {
    let dir = out_dir("restart");
    let scene = scene_path("sphere_bed_a_hertz_5ms.toml");
    let (straight, resumed) = (dir.join("straight"), dir.join("resumed"));
    let network = ["--contacts-interval", "0.0001"];
    run(
        &["run", "--end-time", "0.0005", network[0], network[1]],
        &[("", &scene), ("--out", &straight)],
    );
    run(
        &[
            "run",
            "--end-time",
            "0.0004",
            "--checkpoint-interval",
            "0.00025",
            network[0],
            network[1],
        ],
        &[("", &scene), ("--out", &resumed)],
    );
    let first_checkpoint = std::fs::read_dir(resumed.join("checkpoints"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .min()
        .expect("checkpoints");
    run(
        &["run", "--end-time", "0.0005", network[0], network[1]],
        &[("--restart", &first_checkpoint), ("--out", &resumed)],
    );
    let (a, b) = (
        read(&straight.join("contacts.csv")),
        read(&resumed.join("contacts.csv")),
    );
    // The restart writes the network at its start too (documented): at most one time the straight run
    // has not, dropped before comparing.
    let time = |line: &str| line.split(',').next().unwrap_or("").to_owned();
    let straight_times: std::collections::BTreeSet<String> = a.lines().map(time).collect();
    let extra: std::collections::BTreeSet<String> = b
        .lines()
        .map(time)
        .filter(|t| !straight_times.contains(t))
        .collect();
    assert!(
        extra.len() <= 1,
        "times only in the continued network: {extra:?}"
    );
    let b_without_start: String = b
        .lines()
        .filter(|l| !extra.contains(&time(l)))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(
        a.lines().count() > 20,
        "straight network: {} lines",
        a.lines().count()
    );
    assert!(
        a == b_without_start,
        "the continued network differs from the straight run's ({} against {} lines; restart from {})",
        b_without_start.lines().count(),
        a.lines().count(),
        first_checkpoint.display()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_flat_sphere_layout_writes_the_same_contact_network_as_the_general_step() {
    let bed = scene_path("sphere_bed_a_hertz_5ms.toml");
    let scene = read(&bed);
    let dir = out_dir("flat");
    std::fs::create_dir_all(&dir).unwrap();
    // The same scene with the ledger off (the flat layout's condition), its bed file found from anywhere.
    let bed_file = bed
        .parent()
        .unwrap()
        .join("../reference/sphere_bed/bed_quick.csv");
    let flat_scene = dir.join("sphere_bed_a_no_ledger.toml");
    std::fs::write(
        &flat_scene,
        scene
            .replacen("[simulation]", "[simulation]\nenergy_ledger = false", 1)
            .replacen(
                "\"../reference/sphere_bed/bed_quick.csv\"",
                &format!("{:?}", bed_file.display().to_string()),
                1,
            ),
    )
    .unwrap();
    let (general, flat) = (dir.join("general"), dir.join("flat"));
    for (scene, out) in [(bed, &general), (flat_scene, &flat)] {
        run(&BED_RUN, &[("", &scene), ("--out", out)]);
    }
    assert!(
        read(&flat.join("summary.txt")).contains("flat sphere layout"),
        "{}",
        read(&flat.join("summary.txt"))
    );
    let (a, b) = (
        read(&general.join("contacts.csv")),
        read(&flat.join("contacts.csv")),
    );
    assert!(
        a.lines().count() > 1000,
        "general network: {} lines",
        a.lines().count()
    );
    assert_eq!(a, b, "the flat layout wrote another contact network");
    let _ = std::fs::remove_dir_all(&dir);
}
