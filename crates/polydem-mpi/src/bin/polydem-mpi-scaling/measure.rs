//! One measured run under `mpirun`: the generated scene stepped by [`DistributedRun`], each rank's wall and
//! CPU time, cuts, part and traffic gathered on rank 0, which appends one CSV row per rank.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use polydem::scene::parse_scene;
use polydem_mpi::exchange::GHOST_WORDS;
use polydem_mpi::mpi::traits::*;
use polydem_mpi::plan::ghost_width;
use polydem_mpi::scaling::model::GHOST_BYTES;
use polydem_mpi::scaling::record::{RankRow, HEADER};
use polydem_mpi::scaling::scene::{scene_toml, Lattice, SceneKind};
use polydem_mpi::DistributedRun;

use crate::{Args, Error};

// The model's bytes per ghost are the exchange's.
const _: () = assert!(GHOST_WORDS * 8 == GHOST_BYTES as usize);

/// Steps between two readings of the runnable threads on rank 0.
const SAMPLE_EVERY: u64 = 10;

/// What to run.
pub struct Spec {
    pub run: u32,
    pub scene: SceneKind,
    pub lattice: Lattice,
    pub steps: u64,
    pub csv: PathBuf,
    /// The imbalance above which a cut bisects again ([`polydem_mpi::run::REBALANCE_ABOVE`] unless
    /// `--rebalance-above` says; 0: every cut bisects).
    pub rebalance_above: f64,
}

/// The seed of every scene's velocities: repeats of a configuration are the same run.
pub const SEED: u64 = 1;

impl Spec {
    pub fn from_args(args: &Args) -> Result<Self, Error> {
        let name = args.text("scene")?;
        Ok(Self {
            run: args.number("run")?,
            scene: SceneKind::from_name(name).ok_or_else(|| format!("unknown scene `{name}`"))?,
            lattice: Lattice {
                nx: args.number("nx")?,
                ny: args.number("ny")?,
                nz: args.number("nz")?,
            },
            steps: args.number("steps")?,
            csv: PathBuf::from(args.text("csv")?),
            rebalance_above: match args.0.contains_key("rebalance-above") {
                true => args.number("rebalance-above")?,
                false => polydem_mpi::run::REBALANCE_ABOVE,
            },
        })
    }
}

/// CPU time of this process (s): every thread, including MPICH's progress spinning.
fn process_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime only writes into the timespec we pass.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if rc == 0 {
        ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
    } else {
        f64::NAN
    }
}

/// The one-minute load average and the threads runnable now (`/proc/loadavg`); NaN off Linux.
fn load_now() -> (f64, f64) {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let fields: Vec<&str> = text.split_whitespace().collect();
    let one = fields
        .first()
        .and_then(|f| f.parse().ok())
        .unwrap_or(f64::NAN);
    let runnable = fields
        .get(3)
        .and_then(|f| f.split('/').next())
        .and_then(|f| f.parse().ok())
        .unwrap_or(f64::NAN);
    (one, runnable)
}

fn abort(comm: &impl Communicator, error: impl std::fmt::Display) -> ! {
    eprintln!("rank {}: {error}", comm.rank());
    comm.abort(1)
}

/// What one rank measured over the steps, in the order of [`RankRow`]'s per-rank fields.
struct Timing {
    wall_s: f64,
    cpu_s: f64,
    cut_steps: u64,
    cut_wall_s: f64,
    runnable: f64,
    load_before: f64,
    load_after: f64,
}

fn step_all(run: &mut DistributedRun, steps: u64, comm: &impl Communicator) -> Timing {
    comm.barrier();
    let (load_before, _) = load_now();
    let (mut cut_steps, mut cut_wall_s, mut runnable, mut samples) = (0, 0.0, 0.0, 0.0);
    let (start, cpu0) = (Instant::now(), process_cpu_s());
    for s in 0..steps {
        let (at, cuts) = (Instant::now(), run.cuts);
        run.step().unwrap_or_else(|e| abort(comm, e));
        if run.cuts > cuts {
            cut_steps += 1;
            cut_wall_s += at.elapsed().as_secs_f64();
        }
        if run.rank() == 0 && s % SAMPLE_EVERY == 0 {
            runnable += load_now().1;
            samples += 1.0;
        }
    }
    let (wall_s, cpu_s) = (start.elapsed().as_secs_f64(), process_cpu_s() - cpu0);
    Timing {
        wall_s,
        cpu_s,
        cut_steps,
        cut_wall_s,
        runnable: runnable / samples,
        load_before,
        load_after: load_now().0,
    }
}

/// Runs `spec` on every rank of `MPI_COMM_WORLD`; rank 0 appends the rows.
pub fn measure(spec: &Spec) -> Result<(), Error> {
    let universe = polydem_mpi::mpi::initialize().ok_or("MPI was already initialised")?;
    let comm = universe.world();
    let text = scene_toml(spec.scene, spec.lattice, SEED);
    let sim = parse_scene(&text, Path::new("generated.toml")).unwrap_or_else(|e| abort(&comm, e));
    let r_max = sim.world.radii().iter().copied().fold(0.0, f64::max);
    let width = ghost_width(r_max, sim.world.broad_phase().skin()) / spec.scene.spacing();
    let bodies = sim.world.body_count();
    let mut run = DistributedRun::new(sim.world, sim.params).unwrap_or_else(|e| abort(&comm, e));
    run.set_rebalance_above(spec.rebalance_above);
    let (owned, ghosts) = run.part_size();
    let t = step_all(&mut run, spec.steps, &comm);
    let traffic = run.traffic();
    let mine = [
        t.wall_s,
        t.cpu_s,
        t.cut_steps as f64,
        t.cut_wall_s,
        owned as f64,
        ghosts as f64,
        traffic.ghosts.bytes as f64,
        traffic.ghosts.messages as f64,
        traffic.agreements.bytes as f64,
        traffic.agreements.messages as f64,
        traffic.cuts.bytes as f64,
        traffic.cuts.messages as f64,
    ];
    let size = comm.size() as usize;
    let mut all = vec![0.0; mine.len() * size];
    comm.all_gather_into(&mine[..], &mut all[..]);
    if run.rank() != 0 {
        return Ok(());
    }
    let rows: Vec<RankRow> = all
        .chunks(mine.len())
        .enumerate()
        .map(|(rank, v)| RankRow {
            run: spec.run,
            scene: spec.scene.name().to_owned(),
            ranks: size,
            rank,
            bodies,
            steps: spec.steps,
            wall_s: v[0],
            cpu_s: v[1],
            cut_steps: v[2] as u64,
            cut_wall_s: v[3],
            owned: v[4] as usize,
            ghosts: v[5] as usize,
            ghost_bytes: v[6] as u64,
            ghost_messages: v[7] as u64,
            agreement_bytes: v[8] as u64,
            agreement_messages: v[9] as u64,
            cut_bytes: v[10] as u64,
            cut_messages: v[11] as u64,
            runnable: t.runnable,
            load_before: t.load_before,
            load_after: t.load_after,
            ghost_width_spacings: width,
        })
        .collect();
    append_rows(&spec.csv, &rows)?;
    println!(
        "run {}: {} × {} bodies on {size} ranks, {} steps: {:.2} s (slowest rank), {} cuts, runnable {:.2}",
        spec.run,
        spec.scene.name(),
        bodies,
        spec.steps,
        rows.iter().map(|r| r.wall_s).fold(0.0, f64::max),
        t.cut_steps,
        t.runnable
    );
    Ok(())
}

fn append_rows(path: &Path, rows: &[RankRow]) -> Result<(), Error> {
    let fresh = !path.exists();
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut text = String::new();
    if fresh {
        text.push_str(HEADER);
        text.push('\n');
    }
    for row in rows {
        text.push_str(&row.to_csv());
        text.push('\n');
    }
    file.write_all(text.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()).into())
}
