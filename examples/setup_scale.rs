//! Scene set-up at scale: the seconds and the peak memory per body of reading and building a scene of
//! 10^4, 10^5 and 10^6 spheres and of 10^5 polyhedra, all from `[[body_file]]` tables (the format of
//! `scenes/polyhedra_from_file.toml`), with the set-up work counted by `World::setup_stats`.
//!
//! ```text
//! cargo run --release --example setup_scale -- [--cases spheres:10000,spheres:100000,...] [--dir DIR]
//! ```
//! Each case runs in a child process of this example (so that its peak resident set, `VmHWM` of
//! `/proc/self/status`, is its own): the parent writes the scene and its CSV table into `--dir` (default
//! a temporary directory), the child times `polydem::scene::load_scene` and reports the peak resident set
//! before and after. Memory per body = (peak after − peak before) / bodies: the world's bodies, shapes and
//! names, and the parsed table on the way. The load average is printed with each case (the machine is
//! shared; the seconds are wall time).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use polydem::host::load_average;

/// A case: a kind (`spheres` or `polyhedra`) and a body count.
#[derive(Clone, Copy, Debug)]
struct Case {
    polyhedra: bool,
    bodies: usize,
}

impl Case {
    fn parse(text: &str) -> Result<Self, String> {
        let (kind, n) = text
            .split_once(':')
            .ok_or_else(|| format!("case '{text}': expected KIND:COUNT"))?;
        let bodies = n
            .parse::<f64>()
            .map_err(|e| format!("case '{text}': {e}"))? as usize;
        match kind {
            "spheres" => Ok(Self {
                polyhedra: false,
                bodies,
            }),
            "polyhedra" => Ok(Self {
                polyhedra: true,
                bodies,
            }),
            other => Err(format!("case '{text}': unknown kind '{other}'")),
        }
    }

    fn name(&self) -> String {
        let kind = if self.polyhedra {
            "polyhedra"
        } else {
            "spheres"
        };
        format!("{kind}_{}", self.bodies)
    }
}

const HEADER: &str = r#"[simulation]
gravity = [0.0, 0.0, -9.81]
end_time = 0.01
output_interval = 0.005
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
friction = 0.4

[[box]]
name = "bin"
material = "rock"
min = [-1.0, -1.0, -1.0]
max = [1000.0, 1000.0, 1000.0]
open = ["z+"]
"#;

const SHAPES: &str = r#"
[[shape]]
name = "cube"
kind = "box"
half_extents = [0.005, 0.004, 0.003]

[[shape]]
name = "wedge"
kind = "polyhedron"
points = [
  [-0.005, -0.004, -0.003], [0.005, -0.004, -0.003], [0.0, -0.004, 0.005],
  [-0.005, 0.004, -0.003], [0.005, 0.004, -0.003], [0.0, 0.004, 0.005],
]
"#;

/// Writes the case's scene and table into `dir`; returns the scene's path.
fn write_case(case: &Case, dir: &Path) -> std::io::Result<PathBuf> {
    let name = case.name();
    let table = format!("{name}.csv");
    let mut csv = String::with_capacity(case.bodies * 64);
    csv.push_str(if case.polyhedra {
        "id,shape,x,y,z,qw,qx,qy,qz\n"
    } else {
        "id,x,y,z,radius\n"
    });
    // A cubic lattice 2 cm apart, far enough for bodies of 1 cm.
    let side = (case.bodies as f64).cbrt().ceil() as usize;
    for i in 0..case.bodies {
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let (x, y, z) = (0.02 * x as f64, 0.02 * y as f64, 0.02 * z as f64);
        if case.polyhedra {
            let shape = if i % 2 == 0 { "cube" } else { "wedge" };
            let _ = writeln!(csv, "{i},{shape},{x},{y},{z},1,0,0,0");
        } else {
            let _ = writeln!(csv, "{i},{x},{y},{z},0.005");
        }
    }
    std::fs::write(dir.join(&table), csv)?;
    let mut scene = HEADER.to_owned();
    if case.polyhedra {
        scene.push_str(SHAPES);
    }
    let _ = write!(
        scene,
        "\n[[body_file]]\npath = \"{table}\"\nmaterial = \"rock\"\nname_prefix = \"b\"\n"
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, scene)?;
    Ok(path)
}

/// `VmHWM` of this process (bytes).
fn peak_resident() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

/// The child: loads one scene and prints `seconds peak_before peak_after bodies work`.
fn child(scene: &Path) -> Result<(), String> {
    let before = peak_resident();
    let start = Instant::now();
    let sim = polydem::scene::load_scene(scene).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let after = peak_resident();
    let work = sim.world.setup_stats().total();
    println!(
        "{seconds} {before} {after} {} {work}",
        sim.world.bodies().len()
    );
    Ok(())
}

fn parent(cases: &[Case], dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    println!("case | bodies | set-up (s) | peak memory per body (bytes) | set-up work | work per body | load average before");
    println!("---|---|---|---|---|---|---");
    for case in cases {
        let scene = write_case(case, dir).map_err(|e| e.to_string())?;
        let load = load_average();
        let out = Command::new(&exe)
            .arg("--child")
            .arg(&scene)
            .output()
            .map_err(|e| e.to_string())?;
        if !out.status.success() {
            return Err(format!(
                "{}: {}",
                case.name(),
                String::from_utf8_lossy(&out.stderr)
            ));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        let f: Vec<f64> = text
            .split_whitespace()
            .filter_map(|x| x.parse().ok())
            .collect();
        let [seconds, before, after, bodies, work] = f[..] else {
            return Err(format!("{}: unexpected child output '{text}'", case.name()));
        };
        println!(
            "{} | {bodies} | {seconds:.3} | {:.0} | {work} | {:.2} | {load}",
            case.name(),
            (after - before) / bodies,
            work / bodies
        );
        for ext in ["toml", "csv"] {
            std::fs::remove_file(dir.join(format!("{}.{ext}", case.name()))).ok();
        }
    }
    Ok(())
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, scene] = &args[..] {
        if flag == "--child" {
            return child(Path::new(scene));
        }
    }
    let mut cases = "spheres:1e4,spheres:1e5,spheres:1e6,polyhedra:1e5".to_owned();
    let mut dir = std::env::temp_dir().join(format!("polydem_setup_scale_{}", std::process::id()));
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match (a.as_str(), it.next()) {
            ("--cases", Some(v)) => cases = v.clone(),
            ("--dir", Some(v)) => dir = PathBuf::from(v),
            _ => return Err(format!("unknown or incomplete option '{a}'")),
        }
    }
    let cases: Vec<Case> = cases
        .split(',')
        .map(Case::parse)
        .collect::<Result<_, _>>()?;
    let result = parent(&cases, &dir);
    std::fs::remove_dir_all(&dir).ok();
    result
}
