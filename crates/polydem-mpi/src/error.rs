//! What can stop a distributed run.

use polydem::math::Real;

/// Why a distributed run cannot go on.
#[derive(Debug, thiserror::Error)]
pub enum DistributedError {
    /// More ranks than bodies: some subdomain would be empty.
    #[error("{ranks} ranks for {bodies} bodies: every rank needs at least one body")]
    TooManyRanks {
        /// Ranks asked for.
        ranks: usize,
        /// Bodies in the world.
        bodies: usize,
    },
    /// The parameters let bodies fall asleep: the parts' sleeping sets would not be one process's.
    #[error("sleeping is not supported on several ranks (set sleeping off in the scene)")]
    Sleeping,
    /// A body moved farther between two list rebuilds than the ghost layer allows for.
    #[error(
        "body moved {moved} m since the subdomains were cut, more than the {allowance} m the ghost layer \
         allows for (the time step is too large for the skin)"
    )]
    HaloExceeded {
        /// The largest move since the cut (m).
        moved: Real,
        /// The move the ghost layer covers (m).
        allowance: Real,
    },
    /// A step of this rank's part failed.
    #[error("step of rank {rank}: {source}")]
    Step {
        /// The rank whose part failed.
        rank: usize,
        /// The step's error.
        source: polydem::world::StepError,
    },
    /// A body's centre lies in no subdomain (it is not finite).
    #[error("body {body} has a centre that is not finite: it belongs to no subdomain")]
    NotFinite {
        /// The body's global index.
        body: usize,
    },
    /// A message could not be decoded.
    #[error("message from rank {rank} could not be decoded: {message}")]
    Decode {
        /// The sending rank.
        rank: usize,
        /// The decoder's message.
        message: String,
    },
}
