//! Why a penetration run failed (its own file: the impact steppers return it too).

use polydem::world::{StepError, WorldError};

use super::limits::LimitError;
use super::packing::PackingError;

/// Why a penetration run failed.
#[derive(Debug, thiserror::Error)]
pub enum PenetrationError {
    #[error(transparent)]
    Packing(#[from] PackingError),
    #[error(transparent)]
    World(#[from] WorldError),
    #[error(transparent)]
    Step(#[from] StepError),
    #[error("the bed has only {walls} walls; a packed bed has {expected}")]
    NotABed { walls: usize, expected: usize },
    #[error(transparent)]
    Limit(#[from] LimitError),
    /// [`PenetrationOptions::stop`] asked the run to stop (before a step: the world is at a step boundary).
    #[error("penetration interrupted after {steps} steps")]
    Interrupted { steps: u64 },
    /// An output file of the run could not be opened or written (the message names it).
    #[error("penetration output: {0}")]
    Output(#[from] std::io::Error),
    /// [`PenetrationOptions::distributed`] in a build without MPI.
    #[error(
        "the penetration was asked to run split over MPI ranks, but this build has no MPI (build polydem-rockfill \
         with the `mpi` feature and launch it under mpirun)"
    )]
    NoMpi,
    /// A run split over MPI ranks with sleeping on: the ranks' parts do not carry the sleep state.
    #[error(
        "a penetration split over MPI ranks cannot put rocks to sleep (sleeping.penetration = true): the ranks' \
         parts do not carry the sleep state; set it to false"
    )]
    DistributedSleeping,
    /// The run split over MPI ranks failed (the message names the rank).
    #[cfg(feature = "mpi")]
    #[error(transparent)]
    Distributed(#[from] polydem_mpi::DistributedError),
}
