//! A [`Simulation`] run to its end over the ranks, with its outputs: the engine's [`RunObserver`] (the
//! CSV series, checkpoints, the contact network of [`polydem::io::output::OutputSet`]) on rank 0, and VTK
//! frames as parallel pieces ([`VtkPieces`]) from every rank.
//!
//! Rank 0 decides where each stretch of steps ends (the next step an output reads, at most
//! [`PROGRESS_STEPS`] on) and broadcasts it with whether the output reads the contacts; after the stretch
//! every rank sends its owned bodies (and the contact entries it answers for) to rank 0, which writes them
//! into its whole [`Simulation::world`] and hands it to the observer. The other ranks write nothing but
//! their VTK pieces.

use std::time::Instant;

use polydem::scene::{RunObserver, RunSummary, Simulation, PROGRESS_STEPS};

use mpi::traits::*;

use crate::error::DistributedError;
use crate::pieces::VtkPieces;
use crate::run::DistributedRun;

/// What a distributed run did.
#[derive(Clone, Debug, Default)]
pub struct DistributedSummary {
    /// Steps taken, wall time, and the counters, largest overlap and findings of this rank's part.
    pub part: RunSummary,
    /// Times the subdomains were cut (the first included).
    pub cuts: u64,
    /// Times the state was gathered on rank 0 for the outputs.
    pub gathers: u64,
}

/// Why a distributed run with outputs stopped.
#[derive(Debug, thiserror::Error)]
pub enum ObservedRunError {
    /// The distributed step or an exchange failed.
    #[error(transparent)]
    Run(#[from] DistributedError),
    /// Writing an output failed.
    #[error("rank {rank}: writing output: {source}")]
    Output {
        /// The rank whose output failed.
        rank: usize,
        /// The error.
        source: std::io::Error,
    },
}

/// Runs `sim` from its world's step to its last over every rank with `run` (cut from `sim.world`), handing
/// the state to `observer` on rank 0 (`None` elsewhere) and writing `pieces` on every rank where they are
/// due. Every rank calls it with the same simulation.
pub fn run_observed<O: RunObserver>(
    sim: &mut Simulation,
    run: &mut DistributedRun,
    mut observer: Option<&mut O>,
    mut pieces: Option<&mut VtkPieces>,
) -> Result<DistributedSummary, ObservedRunError> {
    let start = Instant::now();
    let rank = run.rank();
    let output = |source| ObservedRunError::Output { rank, source };
    let first = sim.world.step_index();
    let mut summary = DistributedSummary::default();
    if let Some(observer) = observer.as_deref_mut() {
        observer.observe(sim, first).map_err(output)?;
        observer.progress(first);
    }
    if let Some(pieces) = pieces.as_deref_mut().filter(|p| p.due(first)) {
        let whole = observer.is_some().then_some(&sim.world);
        write_pieces(run, pieces, whole).map_err(output)?;
    }
    let mut done = first;
    while done < sim.steps {
        let (end, wanted, contacts) =
            next_stretch(sim, run, done, observer.as_deref(), pieces.as_deref());
        while done < end {
            let report = run.step()?;
            summary.part.counters.merge(&report.counters);
            let ratio = summary.part.max_overlap_ratio.max(report.max_overlap_ratio);
            summary.part.max_overlap_ratio = ratio;
            done += 1;
        }
        let frame = pieces.as_deref().is_some_and(|p| p.due(end));
        if wanted || frame {
            run.gather_into(observer.is_some().then_some(&mut sim.world), contacts)?;
            summary.gathers += 1;
        }
        if let Some(pieces) = pieces.as_deref_mut().filter(|_| frame) {
            let whole = observer.is_some().then_some(&sim.world);
            write_pieces(run, pieces, whole).map_err(output)?;
        }
        if let Some(observer) = observer.as_deref_mut() {
            if wanted {
                observer.observe(sim, end).map_err(output)?;
            }
            observer.progress(end);
        }
    }
    summary.part.steps = done - first;
    summary.part.wall_time = start.elapsed();
    summary.cuts = run.cuts;
    Ok(summary)
}

/// This rank's pieces of a frame: its owned bodies, and on rank 0 (`whole`, the gathered world) the walls
/// and collections.
fn write_pieces(
    run: &DistributedRun,
    pieces: &mut VtkPieces,
    whole: Option<&polydem::world::World>,
) -> std::io::Result<()> {
    pieces.write(run.part_world(), &run.owned_piece(), whole)
}

/// Rank 0's choice of the next stretch after step `done`, broadcast: its last step, whether the observer
/// reads the state there, and whether it reads the contacts.
fn next_stretch<O: RunObserver>(
    sim: &Simulation,
    run: &DistributedRun,
    done: u64,
    observer: Option<&O>,
    pieces: Option<&VtkPieces>,
) -> (u64, bool, bool) {
    let mut message = [0u64; 3];
    if let Some(observer) = observer {
        let last = sim.steps.min(done + PROGRESS_STEPS);
        let frame = |n: u64| pieces.is_some_and(|p| p.due(n));
        let end = (done + 1..last)
            .find(|&n| observer.wants_state(n) || frame(n))
            .unwrap_or(last);
        let wanted = observer.wants_state(end) || end == sim.steps;
        let contacts = wanted && observer.reads_contacts(end);
        message = [end, wanted as u64, contacts as u64];
    }
    run.communicator()
        .process_at_rank(0)
        .broadcast_into(&mut message[..]);
    (message[0], message[1] != 0, message[2] != 0)
}
