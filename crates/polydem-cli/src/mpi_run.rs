//! `polydem run` under `mpirun -n P` (the feature `mpi`): with more than one rank the scene is stepped split
//! over the ranks ([`polydem_mpi`]), the same bits as one process. Rank 0 writes the CSV series, the
//! checkpoints (in the one format every rank count reads), the contact network, the progress and the
//! summary; every rank writes its VTK pieces (`.pvtu` frames in the `.pvd` series, see
//! [`polydem_mpi::pieces`]). A rank whose set-up, step or output fails prints `rank R: error: …` and aborts
//! the communicator, so every rank stops and `mpirun` exits non-zero.

use anyhow::{Context, Result};
use polydem::io::output::Schedule;
use polydem::io::run_outputs::{interval_steps, RunStart};
use polydem_mpi::mpi::topology::SimpleCommunicator;
use polydem_mpi::mpi::traits::*;
use polydem_mpi::observed::{run_observed, DistributedSummary};
use polydem_mpi::pieces::VtkPieces;
use polydem_mpi::DistributedRun;

use super::RunArgs;

/// `polydem run`: distributed over the ranks of `MPI_COMM_WORLD` when there are several, else the
/// ordinary run.
pub fn run(args: &RunArgs) -> Result<()> {
    let Some(universe) = polydem_mpi::mpi::initialize() else {
        anyhow::bail!("MPI could not be initialised");
    };
    let world = universe.world();
    if world.size() == 1 {
        return super::run(args);
    }
    if let Err(e) = distributed(args, &world) {
        eprintln!("rank {}: error: {}", world.rank(), super::one_line(&e));
        // A moment for the launcher to forward the message before the abort tears the job down.
        std::thread::sleep(std::time::Duration::from_millis(200));
        world.abort(1);
    }
    Ok(())
}

fn distributed(args: &RunArgs, comm: &SimpleCommunicator) -> Result<()> {
    let (rank, ranks) = (comm.rank() as usize, comm.size() as usize);
    let (mut sim, origin, start) = super::load_run(args)?;
    let restarted = matches!(start, RunStart::Restart { .. });
    // Rank 0 opens the outputs of one process but the VTK frames, which every rank writes as pieces.
    let without_vtk = RunArgs {
        vtk_interval: None,
        ..args.clone()
    };
    let mut outputs = match rank {
        0 => Some(super::run_outputs(&without_vtk, &sim, &start)?),
        _ => None,
    };
    let mut pieces = match interval_steps("--vtk-interval", args.vtk_interval, sim.params.dt)? {
        Some(every) => {
            let schedule = Schedule {
                start_step: sim.world.step_index(),
                last_step: sim.steps,
                every: Some(every),
                at_start: true,
                at_end: true,
            };
            let encoding = super::vtk_encoding(args);
            let at = (rank, ranks);
            Some(VtkPieces::new(
                &args.out, &sim.world, encoding, schedule, at, restarted,
            )?)
        }
        None => None,
    };
    let mut run = DistributedRun::new(sim.world.clone(), sim.params)
        .with_context(|| format!("splitting {} over {ranks} ranks", origin.source))?;
    let quiet = args.quiet || rank != 0;
    if !quiet {
        eprintln!("{} on {ranks} ranks", super::run_header(&origin, &sim));
        eprintln!(
            "note: on several ranks energy.csv and the energy terms of checkpoints are added over the ranks, \
             equal to one process's up to rounding (bodies.csv, walls.csv, VTK and the state of \
             checkpoints are one process's bit for bit)"
        );
    }
    let bar = super::progress_bar(quiet, &origin, &sim)?;
    if let Some(outputs) = outputs.as_mut() {
        let (shown, start_step) = (bar.clone(), origin.start_step);
        outputs.on_progress(move |n| shown.set_position(n - start_step));
    }
    let summary = run_observed(&mut sim, &mut run, outputs.as_mut(), pieces.as_mut())
        .with_context(|| format!("running {}", origin.source))?;
    let (Some(outputs), 0) = (outputs, rank) else {
        return Ok(());
    };
    let mut record = outputs.finish()?;
    bar.finish_and_clear();
    if let Some(pieces) = &pieces {
        record.vtk_every = interval_steps("--vtk-interval", args.vtk_interval, sim.params.dt)?;
        record.vtk_frames = pieces.frames_written;
        record.vtk_bytes = pieces.bytes_written;
    }
    let traffic = run.traffic();
    let extra = distributed_lines(ranks, &summary, &traffic);
    super::write_summaries(args, &origin, &sim, &summary.part, &record, &extra)
}

fn distributed_lines(
    ranks: usize,
    summary: &DistributedSummary,
    traffic: &polydem_mpi::exchange::RunTraffic,
) -> String {
    let steps = summary.part.steps.max(1) as f64;
    let per_step = |t: polydem_mpi::exchange::Traffic| t.bytes as f64 / steps;
    let gathered = traffic.received_at_root.bytes as f64 / summary.gathers.max(1) as f64;
    format!(
        "distributed over {ranks} ranks: {} cuts; rank 0 sent per step {:.0} B of ghosts, {:.0} B of \
         agreements, {:.0} B at cuts; {} gathers for the outputs, {gathered:.0} B received per gather (the \
         counters above are rank 0's part, its ghosts included)\n",
        summary.cuts,
        per_step(traffic.ghosts),
        per_step(traffic.agreements),
        per_step(traffic.cuts),
        summary.gathers,
    )
}
