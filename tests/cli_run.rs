//! The `polydem run SCENE --out DIR` contract (issue 3): `bodies.csv` and `energy.csv` with the documented
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
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_polyhedra_elastic.toml");
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
        Some("t,translational_kinetic,rotational_kinetic,elastic_potential,gravitational_potential,dissipated_damping,dissipated_friction,dissipated_viscous,external_work,balance")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect();
    assert_eq!(rows.len() as u64, outputs, "rows in energy.csv");
    assert_eq!(rows[0][9], 0.0, "the balance starts at zero");
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
