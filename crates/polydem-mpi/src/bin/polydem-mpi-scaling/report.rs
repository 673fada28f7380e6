//! The page `reports/mpi.md`, written from the CSV files of a set (`reports/mpi/runs.csv`, `pingpong.csv`,
//! `plan.csv`): the measured runs with their loads, the weak and strong efficiencies, the traffic per
//! step, the network, and the model extrapolated to clusters beside exaDEM's figure.

use std::fmt::Write;
use std::path::Path;

use polydem_mpi::scaling::model::Network;
use polydem_mpi::scaling::record::{median, read_runs, RunFigures, QUIET_FOREIGN_LOAD};

use crate::drive::SCENES;
use crate::extrapolate::{calibrations, model};
use crate::Error;

/// The interconnect assumed for the extrapolation: MPI latency and bandwidth of EDR/HDR InfiniBand.
pub const CLUSTER: Network = Network {
    latency_s: 2.0e-6,
    bandwidth: 10.0e9,
};

/// Rank counts of the extrapolation.
pub const CLUSTER_RANKS: [usize; 7] = [64, 128, 256, 512, 1024, 2048, 4096];

/// exaDEM's polyhedra benchmark: bodies, and the strong-scaling efficiency from 64 to 2048 cores.
pub const EXADEM_BODIES: f64 = 1_651_637.0;
pub const EXADEM_EFFICIENCY: f64 = 0.65;

const COMMAND: &str =
    "MPI_PKG_CONFIG=mpich cargo run --release -p polydem-mpi --features mpi --bin polydem-mpi-scaling -- drive";

/// The repeats of one configuration.
pub struct Group {
    scene: String,
    ranks: usize,
    bodies: usize,
    runs: Vec<RunFigures>,
}

impl Group {
    fn median_of(&self, f: fn(&RunFigures) -> f64) -> f64 {
        median(&mut self.runs.iter().map(f).collect::<Vec<_>>()).unwrap_or(f64::NAN)
    }

    fn fastest_of(&self, f: fn(&RunFigures) -> f64) -> f64 {
        self.runs.iter().map(f).fold(f64::INFINITY, f64::min)
    }

    /// The spread of the repeats' wall times, (slowest − fastest)/median.
    fn wall_spread(&self) -> f64 {
        let slowest = self.runs.iter().map(|r| r.wall_s).fold(0.0, f64::max);
        (slowest - self.fastest_of(|r| r.wall_s)) / self.median_of(|r| r.wall_s)
    }

    /// The repeat whose wall time is the median (the lower middle one for an even count).
    pub fn median_run(&self) -> &RunFigures {
        let mut order: Vec<&RunFigures> = self.runs.iter().collect();
        order.sort_by(|a, b| a.wall_s.total_cmp(&b.wall_s));
        order[(order.len() - 1) / 2]
    }

    /// No repeat had foreign load, and the repeats agree within [`QUIET_SPREAD`].
    pub fn quiet(&self) -> bool {
        self.runs.iter().all(RunFigures::quiet) && self.wall_spread() <= QUIET_SPREAD
    }

    fn foreign_load(&self) -> f64 {
        self.runs
            .iter()
            .map(|r| r.foreign_load)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    fn load_range(&self) -> (f64, f64) {
        let loads = self.runs.iter().flat_map(|r| [r.load_before, r.load_after]);
        loads.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), l| {
            (lo.min(l), hi.max(l))
        })
    }
}

fn groups(runs: Vec<RunFigures>) -> Vec<Group> {
    let mut out: Vec<Group> = Vec::new();
    for run in runs {
        let key = (run.scene.clone(), run.ranks, run.bodies);
        match out
            .iter_mut()
            .find(|g| (g.scene.clone(), g.ranks, g.bodies) == key)
        {
            Some(g) => g.runs.push(run),
            None => out.push(Group {
                scene: key.0,
                ranks: key.1,
                bodies: key.2,
                runs: vec![run],
            }),
        }
    }
    out
}

fn read(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()).into())
}

/// The numeric rows of a small CSV (header skipped).
fn numbers(text: &str) -> Result<Vec<Vec<f64>>, Error> {
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split(',')
                .map(|f| f.parse::<f64>().map_err(|e| format!("`{l}`: {e}").into()))
                .collect()
        })
        .collect()
}

/// Writes `out/mpi.md` and its plots from `out/mpi/*.csv`.
pub fn write(out: &Path) -> Result<(), Error> {
    let dir = out.join("mpi");
    let runs = read_runs(&read(&dir.join("runs.csv"))?)?;
    let pingpong = numbers(&read(&dir.join("pingpong.csv"))?)?;
    let plan = numbers(&read(&dir.join("plan.csv"))?)?;
    let groups = groups(runs);
    let loopback = fit_network(&pingpong)?;
    let plan_slope = fit_plan(&plan)?;
    let mut page = String::new();
    header(&mut page, &groups);
    measured(&mut page, &groups);
    let scalings = scalings(&mut page, &groups)?;
    traffic(&mut page, &groups);
    network(&mut page, &pingpong, &loopback, &plan, plan_slope);
    let calibrations = calibrations(&mut page, &scalings, &loopback, plan_slope)?;
    model(&mut page, &dir, &calibrations)?;
    let path = out.join("mpi.md");
    std::fs::write(&path, page).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

fn git_commit() -> String {
    let run = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
    };
    let commit = run(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_else(|| "n/a".into());
    let dirty =
        run(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
    if dirty {
        format!("{commit}-dirty")
    } else {
        commit
    }
}

fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_owned())
        })
        .unwrap_or_else(|| "n/a".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!("{cores} cores, {cpu}")
}

fn header(page: &mut String, groups: &[Group]) {
    let repeats = groups.iter().map(|g| g.runs.len()).min().unwrap_or(0);
    let _ = writeln!(
        page,
        "# MPI: weak and strong scaling, traffic per step, and a cost model for clusters\n\n\
         Generated by `polydem-mpi-scaling` from the CSV files in [mpi/](mpi/); re-run the whole set \
         (about 5 minutes on 2 cores, on an otherwise idle machine) and rewrite this page with\n\n\
         ```\n{COMMAND}\n```\n\n\
         | | |\n|---|---|\n| commit (page written) | `{}` |\n| machine | {} |\n| MPI | MPICH (`mpirun.mpich`), one rayon thread per rank (`RAYON_NUM_THREADS=1`) |\n\
         | repeats | {repeats} per configuration, run round-robin; times are the **median** repeat |\n",
        git_commit(),
        machine()
    );
    let _ = writeln!(
        page,
        "**Load.** Rank 0 reads the threads runnable on the machine (`/proc/loadavg`) every 10 steps; \
         the mean minus the run's own ranks is the *foreign load*. A configuration whose foreign load \
         exceeded {QUIET_FOREIGN_LOAD} in any repeat is marked **not measured quietly**: its wall times \
         include other programs' work and its ratios are not a measurement of this code. So is one \
         whose repeats' wall times spread by more than {:.0} % of their median: the same run then took \
         different times for reasons outside it (other virtual machines on the host share its cores, \
         which no load figure inside this one shows). CPU time (the process clock, summed over the \
         ranks; MPICH's waits spin and count) is printed beside each wall time.\n",
        100.0 * QUIET_SPREAD
    );
}

/// The largest spread of a configuration's repeats, (slowest − fastest)/median, for a quiet measurement.
const QUIET_SPREAD: f64 = 0.2;

pub fn quiet_note(quiet: bool) -> &'static str {
    if quiet {
        "quiet"
    } else {
        "**not measured quietly**"
    }
}

fn measured(page: &mut String, groups: &[Group]) {
    let _ = writeln!(
        page,
        "## Measured runs\n\nScenes: a lattice of spheres (r = 5 mm) or cubes (polyhedra, half side \
         5 mm) thrown at up to 0.2 m/s per axis into a box open at the top, linear law, Δt = t_c/20 \
         (`polydem_mpi::scaling::scene`). Wall time: the slowest rank's, over the timed steps.\n\n\
         | scene | ranks | bodies | steps | wall (s) | µs per body-step | CPU (s) | cuts | foreign load (max) | 1-min load | status |\n\
         |---|---|---|---|---|---|---|---|---|---|---|"
    );
    for g in groups {
        let wall = g.median_of(|r| r.wall_s);
        let steps = g.runs[0].steps as f64;
        let (lo, hi) = g.load_range();
        let _ = writeln!(
            page,
            "| {} | {} | {} | {} | {wall:.3} | {:.3} | {:.3} | {} | {:.2} | {lo:.2}–{hi:.2} | {} |",
            g.scene,
            g.ranks,
            g.bodies,
            steps,
            wall / steps / g.bodies as f64 * 1e6 * g.ranks as f64,
            g.median_of(|r| r.cpu_s),
            g.median_run().cut_steps,
            g.foreign_load(),
            quiet_note(g.quiet())
        );
    }
    let _ = writeln!(
        page,
        "\nµs per body-step is wall time × ranks / (steps × bodies): the core time one body's step \
         costs (equal on 1 and P ranks for perfect scaling).\n"
    );
}

/// Per scene: (one rank small, one rank doubled, two ranks doubled).
pub struct Scaling<'a> {
    pub scene: &'a str,
    pub small: &'a Group,
    pub big: &'a Group,
    pub two: &'a Group,
}

fn scalings<'a>(page: &mut String, groups: &'a [Group]) -> Result<Vec<Scaling<'a>>, Error> {
    let _ = writeln!(
        page,
        "## Weak and strong scaling on this machine\n\n\
         Weak: one rank on the base lattice against two ranks on the lattice doubled along x (bodies \
         per rank fixed): E = T₁(N)/T₂(2N). Strong: one rank against two on the doubled lattice: \
         E = T₁(2N)/(2 T₂(2N)). The efficiency is taken from the median repeats and, beside it, from the \
         fastest repeat of each configuration (on a shared host, other machines' work only adds time). \
         The spread is that of the repeats' wall times, (slowest − fastest)/median. The CPU ratio is \
         the efficiency's ratio of CPU time per rank (weak) or of total CPU time (strong), medians.\n\n\
         | scene | scaling | wall T₁ (s) | wall T₂ (s) | efficiency | efficiency, fastest repeats | spread T₁ / T₂ | CPU ratio | foreign load (max) | status |\n\
         |---|---|---|---|---|---|---|---|---|---|"
    );
    let mut list = Vec::new();
    for (kind, base, _) in SCENES {
        let find = |ranks: usize, bodies: usize| {
            groups
                .iter()
                .find(|g| g.scene == kind.name() && g.ranks == ranks && g.bodies == bodies)
                .ok_or_else(|| {
                    format!(
                        "{}: no run on {ranks} ranks of {bodies} bodies",
                        kind.name()
                    )
                })
        };
        let n = base.bodies();
        let s = Scaling {
            scene: kind.name(),
            small: find(1, n)?,
            big: find(1, 2 * n)?,
            two: find(2, 2 * n)?,
        };
        let wall = |g: &Group| g.median_of(|r| r.wall_s);
        let fastest = |g: &Group| g.fastest_of(|r| r.wall_s);
        let cpu = |g: &Group| g.median_of(|r| r.cpu_s);
        let rows = [
            ("weak", s.small, 1.0, cpu(s.small) / (cpu(s.two) / 2.0)),
            ("strong", s.big, 0.5, cpu(s.big) / cpu(s.two)),
        ];
        for (name, one, per_rank, cpu_ratio) in rows {
            let quiet = one.quiet() && s.two.quiet();
            let _ = writeln!(
                page,
                "| {} | {name} | {:.3} | {:.3} | {:.1} % | {:.1} % | {:.0} % / {:.0} % | {cpu_ratio:.3} | {:.2} | {} |",
                s.scene,
                wall(one),
                wall(s.two),
                100.0 * per_rank * wall(one) / wall(s.two),
                100.0 * per_rank * fastest(one) / fastest(s.two),
                100.0 * one.wall_spread(),
                100.0 * s.two.wall_spread(),
                one.foreign_load().max(s.two.foreign_load()),
                quiet_note(quiet)
            );
        }
        list.push(s);
    }
    let _ = writeln!(
        page,
        "\nThe issue asks for a weak-scaling efficiency of at least 80 % measured quietly; a row marked \
         not measured quietly does not decide it either way. On a loaded machine two ranks suffer \
         more than one: every step has collectives (the agreement, the ghost exchange) that need both \
         ranks on a core at once, and MPICH waits by spinning, so a rank waiting for a descheduled \
         partner burns its own time slice (the CPU column counts that spinning).\n"
    );
    Ok(list)
}

fn traffic(page: &mut String, groups: &[Group]) {
    let _ = writeln!(
        page,
        "## Communication per step\n\n\
         Payload bytes and messages sent per step, summed over the ranks (the median repeat; exact \
         counts, from the sizes of the buffers handed to MPI: MPI's own headers are not counted). \
         Ghosts: 19 f64 (152 B) per ghost after each step without a cut; agreements: one all-reduce \
         of 4 f64 per rank at each rebuild decision (the bytes each rank hands to it; messages: the \
         all-reduces); cuts: each owner's bodies and contact entries to \
         the near ranks that hold them next (postcard), one message each way between near ranks, spread \
         over the steps.\n\n\
         | scene | ranks | bodies | ghosts / bodies | ghost B/step | ghost msg/step | agreement B/step | agreement msg/step | cut B/step | cut msg/step | steps per cut |\n\
         |---|---|---|---|---|---|---|---|---|---|---|"
    );
    for g in groups.iter().filter(|g| g.ranks > 1) {
        let r = g.median_run();
        let [gh, ag, cu] = r.per_step;
        let per_cut = if r.cut_steps > 0 {
            format!("{:.1}", r.steps as f64 / r.cut_steps as f64)
        } else {
            "no cut".into()
        };
        let _ = writeln!(
            page,
            "| {} | {} | {} | {:.3} | {:.0} | {:.3} | {:.1} | {:.3} | {:.0} | {:.3} | {per_cut} |",
            g.scene, g.ranks, g.bodies, r.ghost_fraction, gh.0, gh.1, ag.0, ag.1, cu.0, cu.1
        );
    }
    let _ = writeln!(page);
}

/// The α–β fit of the ping-pong: α the least one-way time of the messages up to 512 B (on a shared
/// machine the smallest size alone can catch a descheduled rank), β from the largest message.
fn fit_network(rows: &[Vec<f64>]) -> Result<Network, Error> {
    let last = rows.last().ok_or("pingpong.csv has no rows")?;
    let latency_s = rows
        .iter()
        .filter(|r| r[0] <= 512.0)
        .map(|r| r[2])
        .fold(f64::INFINITY, f64::min);
    if !latency_s.is_finite() || last[2] <= latency_s {
        return Err(
            "pingpong.csv: no message of up to 512 B, or the largest is not the slowest".into(),
        );
    }
    let bandwidth = last[0] / (last[2] - latency_s);
    Ok(Network {
        latency_s,
        bandwidth,
    })
}

/// The plan's time per body and rank: the least-squares slope of time against ranks, over the bodies.
fn fit_plan(rows: &[Vec<f64>]) -> Result<f64, Error> {
    let n = rows.len() as f64;
    if n < 2.0 {
        return Err("plan.csv needs two rank counts".into());
    }
    let (mx, my) = (
        rows.iter().map(|r| r[1]).sum::<f64>() / n,
        rows.iter().map(|r| r[2]).sum::<f64>() / n,
    );
    let sxy: f64 = rows.iter().map(|r| (r[1] - mx) * (r[2] - my)).sum();
    let sxx: f64 = rows.iter().map(|r| (r[1] - mx).powi(2)).sum();
    Ok((sxy / sxx / rows[0][0]).max(0.0))
}

fn network(page: &mut String, pingpong: &[Vec<f64>], fit: &Network, plan: &[Vec<f64>], slope: f64) {
    let _ = writeln!(
        page,
        "## This machine's MPI (loopback ping-pong)\n\n\
         | bytes | round trips | one way (µs) | 1-min load before → after |\n|---|---|---|---|"
    );
    for r in pingpong {
        let _ = writeln!(
            page,
            "| {:.0} | {:.0} | {:.2} | {:.2} → {:.2} |",
            r[0],
            r[1],
            r[2] * 1e6,
            r[3],
            r[4]
        );
    }
    let _ = writeln!(
        page,
        "\nFit: α = {:.2} µs (the least one-way time up to 512 B), β = {:.2} GB/s (from 1 MiB). Shared memory between two processes on \
         2 cores that other programs also use: a measurement of this machine, not of a network.\n\n\
         **The plan.** At a bisection (the first cut, and a re-bisection when the owned counts drift \
         apart) every rank computes every rank's part ([`Plan::new`]: bisection, then P regions × N \
         centres). Best of 3 on a lattice:\n\n| bodies | ranks | time (ms) |\n|---|---|---|",
        fit.latency_s * 1e6,
        fit.bandwidth * 1e-9
    );
    for r in plan {
        let _ = writeln!(page, "| {:.0} | {:.0} | {:.2} |", r[0], r[1], r[2] * 1e3);
    }
    let _ = writeln!(
        page,
        "\nSlope: {:.2} ns per body and rank (the O(N P) term of a whole-world cut).\n",
        slope * 1e9
    );
}
