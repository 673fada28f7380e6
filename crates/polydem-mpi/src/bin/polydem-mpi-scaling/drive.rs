//! The whole set: every configuration under `mpirun`, repeated round-robin (so a burst of load on the
//! machine spreads over the configurations instead of hitting one), the ping-pong, the plan's cost, and
//! the page.
//!
//! Per scene, three configurations give both scalings with the rayon pool of each rank at one thread:
//! one rank on the base lattice, one rank on the lattice doubled along x, two ranks on the doubled one.
//! Weak scaling compares the first and the third (the bodies per rank fixed), strong the second and the
//! third (the world fixed).

use std::path::Path;
use std::time::Instant;

use polydem::math::Point;
use polydem_mpi::plan::Plan;
use polydem_mpi::scaling::scene::{Lattice, SceneKind};

use crate::Error;

/// A scene's base lattice (one rank's share in the weak scaling) and the steps of each run.
pub const SCENES: [(SceneKind, Lattice, u64); 2] = [
    (
        SceneKind::Spheres,
        Lattice {
            nx: 10,
            ny: 20,
            nz: 20,
        },
        400,
    ),
    (
        SceneKind::Polyhedra,
        Lattice {
            nx: 8,
            ny: 16,
            nz: 16,
        },
        300,
    ),
];

/// The plan is timed on a lattice of this side for these rank counts.
const PLAN_SIDE: usize = 32;
const PLAN_RANKS: [usize; 4] = [1, 16, 64, 256];

/// The header of `plan.csv`.
pub const PLAN_HEADER: &str = "bodies,ranks,seconds";

/// The configurations: (scene, ranks, lattice, steps).
pub fn configurations() -> Vec<(SceneKind, usize, Lattice, u64)> {
    let mut list = Vec::new();
    for (scene, base, steps) in SCENES {
        let doubled = Lattice {
            nx: 2 * base.nx,
            ..base
        };
        list.push((scene, 1, base, steps));
        list.push((scene, 1, doubled, steps));
        list.push((scene, 2, doubled, steps));
    }
    list
}

fn launch(ranks: usize, args: &[String]) -> Result<(), Error> {
    let exe = std::env::current_exe()?;
    let mpirun = polydem_mpi::launch::mpirun();
    let status = polydem_mpi::launch::command(ranks, &exe)
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .status()
        .map_err(|e| format!("{mpirun} could not be started: {e}"))?;
    if !status.success() {
        return Err(format!("{mpirun} -n {ranks} {args:?}: {status}").into());
    }
    Ok(())
}

/// Runs the set into `out/mpi/` and writes `out/mpi.md`.
pub fn drive(out: &Path, repeats: usize) -> Result<(), Error> {
    let dir = out.join("mpi");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let csv = dir.join("runs.csv");
    if csv.exists() {
        std::fs::remove_file(&csv).map_err(|e| format!("{}: {e}", csv.display()))?;
    }
    let start = Instant::now();
    let mut run = 0u32;
    for _ in 0..repeats {
        for (scene, ranks, lattice, steps) in configurations() {
            run += 1;
            let args: Vec<String> = [
                "measure",
                "--run",
                &run.to_string(),
                "--scene",
                scene.name(),
                "--nx",
                &lattice.nx.to_string(),
                "--ny",
                &lattice.ny.to_string(),
                "--nz",
                &lattice.nz.to_string(),
                "--steps",
                &steps.to_string(),
                "--csv",
                &csv.display().to_string(),
            ]
            .map(str::to_owned)
            .to_vec();
            launch(ranks, &args)?;
        }
    }
    let pingpong = dir.join("pingpong.csv").display().to_string();
    launch(2, &["pingpong".to_owned(), "--csv".to_owned(), pingpong])?;
    time_plan(&dir.join("plan.csv"))?;
    println!("measured in {:.0} s", start.elapsed().as_secs_f64());
    crate::report::write(out)
}

/// Times [`Plan::new`] (the best of three) on a cubic lattice for several rank counts.
fn time_plan(path: &Path) -> Result<(), Error> {
    let n = PLAN_SIDE;
    let centres: Vec<Point> = (0..n * n * n)
        .map(|k| Point::new((k % n) as f64, ((k / n) % n) as f64, (k / (n * n)) as f64))
        .collect();
    let radii = vec![0.45; centres.len()];
    let mut text = format!("{PLAN_HEADER}\n");
    for ranks in PLAN_RANKS {
        let best = (0..3)
            .map(|_| {
                let start = Instant::now();
                let plan = Plan::new(&centres, &radii, 0.1, ranks).map(|p| p.parts.len());
                (start.elapsed().as_secs_f64(), plan)
            })
            .map(|(t, plan)| plan.map(|_| t))
            .collect::<Result<Vec<f64>, _>>()?
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        text.push_str(&format!("{},{ranks},{best:e}\n", centres.len()));
    }
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()).into())
}
