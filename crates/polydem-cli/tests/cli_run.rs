//! The `polydem run SCENE --out DIR` contract: `bodies.csv` and `energy.csv` with the documented
//! headers, one row per tracked body per output time, a summary on stdout and in `summary.txt`, and a
//! non-zero exit with the scene file named for a bad scene.

use std::path::Path;
use std::process::Command;

fn out_dir(case: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("polydem-cli-run-{}-{case}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn run_writes_the_documented_csv_files_and_summary() {
    let scene = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("scenes/two_polyhedra_elastic.toml");
    let out = out_dir("two_body");
    let output = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("polydem runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "polydem run failed: {stderr}");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.contains("steps") && stdout.contains("gjk"),
        "summary on stdout: {stdout}"
    );

    let bodies = std::fs::read_to_string(out.join("bodies.csv")).expect("bodies.csv");
    let mut lines = bodies.lines();
    assert_eq!(
        lines.next(),
        Some("t,id,x,y,z,vx,vy,vz,qw,qx,qy,qz,wx,wy,wz")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(
        rows.iter().all(|r| r.len() == 15),
        "every row has 15 columns"
    );
    // Two tracked bodies; an output row at t = 0, every output interval, and at the end.
    let sim = polydem::scene::load_scene(&scene).unwrap();
    let outputs =
        1 + sim.steps / sim.output_every + u64::from(!sim.steps.is_multiple_of(sim.output_every));
    assert_eq!(rows.len() as u64, 2 * outputs, "rows in bodies.csv");
    assert_eq!(rows[0][1], "a");
    assert_eq!(rows[1][1], "b");
    // The first row echoes the scene's initial state: x velocity of body a is +1 m/s.
    assert_eq!(rows[0][5].parse::<f64>().unwrap(), 1.0);

    let energy = std::fs::read_to_string(out.join("energy.csv")).expect("energy.csv");
    let mut lines = energy.lines();
    assert_eq!(
        lines.next(),
        Some("t,translational_kinetic,rotational_kinetic,elastic_potential,gravitational_potential,dissipated_damping,dissipated_friction,dissipated_viscous,external_work,tangential_stiffness_work,balance")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect();
    assert_eq!(rows.len() as u64, outputs, "rows in energy.csv");
    assert_eq!(rows[0][10], 0.0, "the balance starts at zero");
    let walls = std::fs::read_to_string(out.join("walls.csv")).expect("walls.csv");
    assert_eq!(walls.lines().next(), Some("t,wall,fx,fy,fz"));
    assert_eq!(
        walls.lines().count(),
        1,
        "the scene has no walls: header only"
    );
    let summary = std::fs::read_to_string(out.join("summary.txt")).expect("summary.txt");
    assert!(summary.contains("particle-steps per second"), "{summary}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn run_of_a_bad_scene_fails_naming_the_file() {
    let dir = out_dir("bad");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("bad.toml");
    std::fs::write(&scene, "[simulation]\ngravity = [0.0, 0.0]\n").unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_polydem"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .expect("polydem runs");
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains(&format!("{}:2:", scene.display())),
        "stderr: {stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn polydem(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args(args)
        .output()
        .expect("polydem runs")
}

/// Runs polydem and asserts it succeeded (the failure shows the arguments and standard error).
fn succeeds(args: &[&std::ffi::OsStr]) -> std::process::Output {
    let o = polydem(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn scene_path(name: &str) -> std::path::PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("scenes")
        .join(name)
}

/// Runs `polydem run` with `args`, expects failure without a panic, returns standard error.
fn fails(args: &[&std::ffi::OsStr]) -> String {
    let output = polydem(args);
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(
        !output.status.success(),
        "polydem {args:?} succeeded; stderr: {stderr}"
    );
    assert!(
        !stderr.contains("panicked"),
        "polydem {args:?} panicked: {stderr}"
    );
    stderr
}

#[test]
fn bad_input_fails_with_a_message_naming_what_is_wrong() {
    let dir = out_dir("bad_input");
    std::fs::create_dir_all(&dir).unwrap();
    let os = |s: &str| std::ffi::OsString::from(s);
    let scene = scene_path("cube_drop.toml");
    let out = dir.join("out");

    // A missing scene file.
    let missing = dir.join("no_such_scene.toml");
    let err = fails(&[
        &os("run"),
        missing.as_os_str(),
        &os("--out"),
        out.as_os_str(),
    ]);
    assert!(
        err.contains(&missing.display().to_string()) && err.contains("cannot read the scene file"),
        "{err}"
    );

    // An output directory that cannot be created (its parent is a regular file).
    let file = dir.join("a_file");
    std::fs::write(&file, "x").unwrap();
    let bad_out = file.join("out");
    let err = fails(&[
        &os("run"),
        scene.as_os_str(),
        &os("--out"),
        bad_out.as_os_str(),
    ]);
    assert!(
        err.contains("cannot create output directory")
            && err.contains(&bad_out.display().to_string()),
        "{err}"
    );

    // Bad restart files: missing, foreign, truncated.
    let err = fails(&[
        &os("run"),
        &os("--restart"),
        missing.as_os_str(),
        &os("--out"),
        out.as_os_str(),
    ]);
    assert!(
        err.contains("cannot restart from checkpoint") && err.contains("no_such_scene"),
        "{err}"
    );
    let err = fails(&[
        &os("run"),
        &os("--restart"),
        scene.as_os_str(),
        &os("--out"),
        out.as_os_str(),
    ]);
    assert!(err.contains("not a polydem checkpoint"), "{err}");
    let sim = polydem::scene::load_scene(&scene).unwrap();
    let bytes = polydem::io::checkpoint::encode(&sim).unwrap();
    let cut = dir.join("cut.pdck");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let err = fails(&[
        &os("run"),
        &os("--restart"),
        cut.as_os_str(),
        &os("--out"),
        out.as_os_str(),
    ]);
    assert!(
        err.contains("truncated checkpoint") && err.contains("cut.pdck"),
        "{err}"
    );

    // Non-positive or non-finite intervals and end times.
    for (flag, value) in [
        ("--vtk-interval", "0"),
        ("--vtk-interval", "NaN"),
        ("--checkpoint-interval", "-1"),
        ("--end-time", "-2"),
        ("--end-time", "inf"),
    ] {
        let err = fails(&[
            &os("run"),
            scene.as_os_str(),
            &os("--out"),
            out.as_os_str(),
            &os(flag),
            &os(value),
        ]);
        assert!(
            err.contains(flag) || err.contains("end time"),
            "{flag} {value}: {err}"
        );
    }
    // A scene and --restart together, or neither.
    let err = fails(&[
        &os("run"),
        scene.as_os_str(),
        &os("--restart"),
        cut.as_os_str(),
        &os("--out"),
        out.as_os_str(),
    ]);
    assert!(err.contains("--restart"), "{err}");
    let err = fails(&[&os("run"), &os("--out"), out.as_os_str()]);
    assert!(err.contains("SCENE") || err.contains("scene"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The CLI path of a restart: a run to t = 2T with a checkpoint at T, restarted from it, ends with the same
/// last rows in bodies.csv and energy.csv as the straight run; summary.json says what happened.
#[test]
fn restart_through_the_cli_continues_to_the_same_final_rows() {
    let dir = out_dir("restart");
    let scene = scene_path("settling_box.toml");
    let os = |s: &str| std::ffi::OsString::from(s);
    let straight = dir.join("straight");
    let first = dir.join("first");
    let second = dir.join("second");
    let run = succeeds;
    run(&[
        &os("run"),
        scene.as_os_str(),
        &os("--out"),
        straight.as_os_str(),
        &os("--end-time"),
        &os("0.2"),
        &os("--quiet"),
    ]);
    run(&[
        &os("run"),
        scene.as_os_str(),
        &os("--out"),
        first.as_os_str(),
        &os("--end-time"),
        &os("0.1"),
        &os("--checkpoint-interval"),
        &os("0.1"),
        &os("--vtk-interval"),
        &os("0.05"),
        &os("--quiet"),
    ]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(first.join("summary.json")).unwrap())
            .unwrap();
    let checkpoints = summary["outputs"]["checkpoints"]
        .as_array()
        .expect("checkpoint list");
    assert_eq!(checkpoints.len(), 1, "{summary}");
    let file = first.join(checkpoints[0]["file"].as_str().unwrap());
    assert!(first.join("polyhedra.pvd").exists() && first.join("walls.pvd").exists());
    let output = run(&[
        &os("run"),
        &os("--restart"),
        file.as_os_str(),
        &os("--out"),
        second.as_os_str(),
        &os("--end-time"),
        &os("0.2"),
        &os("--quiet"),
    ]);
    assert!(
        output.stderr.is_empty(),
        "--quiet: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    for csv in ["bodies.csv", "energy.csv", "walls.csv"] {
        let a = std::fs::read_to_string(straight.join(csv)).unwrap();
        let b = std::fs::read_to_string(second.join(csv)).unwrap();
        let tail = |s: &str, n: usize| {
            s.lines()
                .rev()
                .take(n)
                .map(str::to_owned)
                .collect::<Vec<_>>()
        };
        assert_eq!(tail(&a, 5), tail(&b, 5), "last rows of {csv}");
    }
    let s2: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(second.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(s2["restarted"], true);
    assert_eq!(s2["start_step"], checkpoints[0]["step"]);
    let s1: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(straight.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(s2["end_step"], s1["end_step"]);
    assert_eq!(s2["energy"], s1["energy"], "final energy ledger");
    for key in [
        "broad",
        "narrow",
        "laws",
        "accumulate",
        "integrate",
        "checks",
        "output",
    ] {
        assert!(
            s1["stage_seconds"][key].is_f64(),
            "stage_seconds.{key} in {s1}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A restart into the directory of the earlier run continues its outputs: the CSV series equal the straight
/// run's byte for byte, and each `.pvd` lists the same frames. The restart rewinds: it starts from the
/// earlier run's first checkpoint (at an output time), not its last, so the earlier rows and frames after
/// that point are replaced.
#[test]
fn restart_into_the_same_directory_continues_the_csv_and_vtk_series() {
    let dir = out_dir("restart-same-dir");
    let scene = scene_path("settling_box.toml");
    let os = |s: &str| std::ffi::OsString::from(s);
    let straight = dir.join("straight");
    let resumed = dir.join("resumed");
    let run = succeeds;
    let vtk = ["--vtk-interval", "0.05"].map(os);
    run(&[
        &os("run"),
        scene.as_os_str(),
        &os("--out"),
        straight.as_os_str(),
        &os("--end-time"),
        &os("0.2"),
        &vtk[0],
        &vtk[1],
        &os("--quiet"),
    ]);
    // Checkpoints every 5 output intervals: the 6th row's time is 5 intervals in whole steps.
    let energy = std::fs::read_to_string(straight.join("energy.csv")).unwrap();
    let five_outputs = energy.lines().nth(6).unwrap().split(',').next().unwrap();
    run(&[
        &os("run"),
        scene.as_os_str(),
        &os("--out"),
        resumed.as_os_str(),
        &os("--end-time"),
        &os("0.16"),
        &os("--checkpoint-interval"),
        &os(five_outputs),
        &vtk[0],
        &vtk[1],
        &os("--quiet"),
    ]);
    let first_checkpoint = std::fs::read_dir(resumed.join("checkpoints"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .min()
        .expect("checkpoints");
    run(&[
        &os("run"),
        &os("--restart"),
        first_checkpoint.as_os_str(),
        &os("--out"),
        resumed.as_os_str(),
        &os("--end-time"),
        &os("0.2"),
        &vtk[0],
        &vtk[1],
        &os("--quiet"),
    ]);
    for csv in ["bodies.csv", "energy.csv", "walls.csv"] {
        let a = std::fs::read_to_string(straight.join(csv)).unwrap();
        let b = std::fs::read_to_string(resumed.join(csv)).unwrap();
        assert!(
            a == b,
            "{csv}: the continued series differs from the straight run's ({} against {} lines; \
             restart from {})",
            b.lines().count(),
            a.lines().count(),
            first_checkpoint.display()
        );
    }
    // The restart writes a frame at its start (documented), here between two frames of the interval.
    let start_step = first_checkpoint
        .file_stem()
        .and_then(|s| s.to_str())
        .and_then(|s| s.strip_prefix("step_"))
        .expect("checkpoint named step_<step>.pdck");
    for pvd in ["polyhedra.pvd", "walls.pvd"] {
        let a = std::fs::read_to_string(straight.join(pvd)).unwrap();
        let b = std::fs::read_to_string(resumed.join(pvd)).unwrap();
        let start_frame = format!("_{start_step}.vtu");
        let without_start: String = b
            .lines()
            .filter(|line| !line.contains(&start_frame))
            .map(|line| format!("{line}\n"))
            .collect();
        assert_eq!(
            b.lines().count(),
            a.lines().count() + 1,
            "{pvd}: one frame more than the straight run (the restart's start)"
        );
        assert_eq!(
            a, without_start,
            "{pvd}: the continued collection lists other frames"
        );
        assert_eq!(
            a.matches("<DataSet").count(),
            5,
            "{pvd}: frames at 0, 0.05, …, 0.2"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A world of free spheres runs on the flat sphere layout, energy ledger included, and `polydem run`
/// writes the same bodies, walls and energy series as on the general step (taken here by a global
/// viscous damping of rate 0, which the flat layout refuses and which changes no bit of the general
/// step: its terms are exact no-ops at c = 0).
#[test]
fn the_flat_sphere_layout_writes_the_same_series_as_the_general_step() {
    let scene = std::fs::read_to_string(scene_path("sphere_bounce.toml")).expect("scene");
    let general_dir = out_dir("general_layout");
    std::fs::create_dir_all(&general_dir).unwrap();
    let general_scene = general_dir.join("sphere_bounce_zero_damping.toml");
    std::fs::write(
        &general_scene,
        scene.replacen(
            "[simulation]",
            "[simulation]\nviscous_damping_rate = 0.0",
            1,
        ),
    )
    .unwrap();
    let general = general_dir.join("out");
    let flat = out_dir("flat_layout");
    for (scene, out) in [
        (general_scene, &general),
        (scene_path("sphere_bounce.toml"), &flat),
    ] {
        succeeds(&[
            "run".as_ref(),
            scene.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--quiet".as_ref(),
        ]);
    }
    let summary = |dir: &Path| std::fs::read_to_string(dir.join("summary.txt")).unwrap();
    assert!(
        summary(&general).contains("general step"),
        "{}",
        summary(&general)
    );
    assert!(
        summary(&flat).contains("flat sphere layout"),
        "{}",
        summary(&flat)
    );
    for file in ["bodies.csv", "walls.csv", "energy.csv"] {
        let (a, b) = (
            std::fs::read_to_string(general.join(file)).unwrap(),
            std::fs::read_to_string(flat.join(file)).unwrap(),
        );
        assert!(
            a.lines().count() > 10,
            "{file}: {} lines",
            a.lines().count()
        );
        assert_eq!(
            a, b,
            "{file}: the flat layout wrote other rows than the general step"
        );
    }
    let _ = std::fs::remove_dir_all(&general_dir);
    let _ = std::fs::remove_dir_all(&flat);
}
