//! polydem over MPI: one world split over processes, bitwise equal to one process for any rank count.
//!
//! # Design
//! - **Where the code lives.** This crate holds the decomposition, the exchanges and the distributed step;
//!   the engine offers its seams in `polydem::world`: [`World::part`](polydem::world::World::part) cuts a
//!   world down to some bodies, [`World::count_only`](polydem::world::World::count_only) marks the ones a
//!   part owns, [`World::copy_body_from_owner`](polydem::world::World::copy_body_from_owner) writes a
//!   ghost's state and loads, [`evaluate_initial_loads`](polydem::world::evaluate_initial_loads) runs a
//!   fresh world's stage 0 alone, and a [`RebuildConsensus`](polydem::world::RebuildConsensus) set on the
//!   step's scratch takes the broad-phase rebuild decision. A run without MPI takes none of them.
//! - **Subdomains** ([`decomposition`]): recursive coordinate bisection balanced by body count, at the
//!   start and again when the owned counts drift apart by more than [`run::REBALANCE_ABOVE`]; in between
//!   the subdomains stay and bodies migrate.
//! - **Parts** ([`plan`]): a rank steps the bodies it owns and the ghosts within reach of them: a body is
//!   held where its bounding radius, the largest one the rank owns, the skin and twice the move a body may
//!   make between rebuilds reach the rank's subdomain (so a projectile widens its owner's layer only),
//!   numbered in global order. The engine sums a
//!   body's forces over its pairs in key order (lower partners by increasing index, higher ones, walls) and
//!   integrates one body at a time, so an owned body gets the bits it gets in one process.
//! - **Ghosts** are stepped with the rest of the part, then overwritten after each step by their owners'
//!   states and loads: the next step's first kick and drift of a ghost then repeat its owner's exactly, so
//!   every pair with an owned body is evaluated on the state one process has. A fresh world's initial
//!   loads are evaluated by each part before the first step and its ghosts' then taken from their owners
//!   (a ghost's own pairs reach beyond the layer). Walls are on every rank.
//! - **Rebuilds** are agreed ([`consensus`]): the two largest moves of the whole world decide, as in one
//!   process. After a rebuild the parts are cut again by migration (`migrate`): each owner sends its
//!   bodies to the near ranks that hold them next (the owner of the subdomain the centre lies in, the
//!   ranks whose ghost layer it lies in), and the contact entries it answers for (tangential springs,
//!   solver caches) to the new owners of their bodies, one message each way between near ranks. A part takes over the list its step just
//!   built where few bodies are new to it, and drops the pairs of two ghosts (they only move ghosts).
//!
//! - **Restarts** ([`DistributedRun::new`]): a world restored from a checkpoint (written by any number of
//!   ranks: the format is one) is cut at the centres its broad phase was built at, as if the cut had
//!   happened at that build, and each part takes the whole list restricted to its bodies; the rebuild
//!   decision and the ghost allowance then count the moves since that build, as one process does.
//! - **Outputs** ([`observed`]): rank 0 holds the whole [`Simulation`](polydem::scene::Simulation) and
//!   hands it to the engine's observer (CSV series, checkpoints, contact network) at the steps it asks
//!   for, after every rank sent it its owned bodies ([`gather`]); for a checkpoint also the contact entries
//!   and the whole broad phase, rebuilt on rank 0 from the positions and walls of the last cut (the list
//!   is a function of them) with the build count the parts keep. VTK frames are parallel pieces
//!   ([`pieces`]). `polydem run` takes this path under `mpirun` with more than one rank (feature `mpi` of
//!   `polydem-cli`).
//!
//! # What is bitwise
//! On any number of ranks, equal to one process: every body's state and loads, `bodies.csv`, the walls'
//! forces (`walls.csv`, summed on rank 0 from the touching body–wall entries in key order, as the step
//! sums them), the VTK pieces' data body by body, and a checkpoint's bodies, loads per body, walls, clock,
//! contact store and broad phase. A checkpoint saved on P ranks continues on Q ranks (or without MPI) to
//! the bits of the uninterrupted run. A scene of spheres only, which one process runs on the flat sphere
//! layout, has one difference of form: one process's checkpoint holds the layout's own lists (no broad
//! phase, an entry per listed pair) where this one holds the general step's; the touching entries are
//! equal and a restart from either gives the same bits.
//!
//! # Building and testing
//! `cargo test --release -p polydem-mpi --features mpi` with `MPI_PKG_CONFIG=mpich` (rsmpi then links
//! Debian's MPICH even where `mpicc` points at Open MPI); `tests/mpi_bits.rs` launches itself with
//! `mpirun.mpich -n 1..4` and compares every body's state with one process's, bit for bit. The command
//! line's test (`crates/polydem-cli/tests/cli_mpi.rs`, feature `mpi`) runs `polydem run` on 2 to 4 ranks
//! and compares its files with one process's, restarts across rank counts, and stops a run whose rank 0
//! fails. `.ci/mpi.sh` installs the packages and runs both. Without the feature the crate builds its
//! MPI-free parts only (decomposition, plan), so the workspace needs no MPI.
//!
//! # What is the whole world's up to rounding
//! The energy sums ([`EnergyShare`](polydem::world::EnergyShare)): each part counts the bodies it owns and
//! the pairs it answers for ([`World::count_only`](polydem::world::World::count_only)), books its share
//! of the ledger across cuts, and an output adds the ranks' shares on rank 0 in rank order. `energy.csv`
//! and a checkpoint's ledger and energy sums are then one process's up to the rounding of that grouping,
//! not bit for bit; the state does not depend on them.
//!
//! # Limits of this stage
//! - Sleeping is refused ([`DistributedError::Sleeping`]); the time-step check does not run on the parts.
//! - Every rank keeps the whole world's fixed data (shapes, names, radii, materials) for the bodies that
//!   migrate to it: O(N) memory. A re-bisection gathers every owned centre on every rank (O(N) traffic,
//!   28 B per body before encoding) and bisects them there (O(N log N)); the bodies then migrate from any
//!   rank to any rank (P messages per rank). An output step gathers the owned bodies on rank 0 (O(N)
//!   there). The ghost exchange and the migration
//!   are point to point between ranks that share bodies; the rebuild agreement is one all-reduce of four
//!   numbers at every step (O(log P)).
//! - A rank whose step or output fails returns the error; the caller aborts the communicator
//!   (`polydem run` prints `rank R: error: …` and does), else the others wait in the next collective.
//! - Subdomains by recursive bisection of the body centres never leave a rank without a body (P larger
//!   than the bodies is refused, [`DistributedError::TooManyRanks`]); a body larger than its subdomain is
//!   covered, since the ghost layer of its owner is sized by its bounding radius.

pub mod decomposition;
pub mod error;
pub mod launch;
pub mod plan;
pub mod scaling;

#[cfg(feature = "mpi")]
pub mod consensus;
#[cfg(feature = "mpi")]
pub mod exchange;
#[cfg(feature = "mpi")]
pub mod gather;
#[cfg(feature = "mpi")]
mod migrate;
#[cfg(feature = "mpi")]
pub mod observed;
#[cfg(feature = "mpi")]
pub mod pieces;
#[cfg(feature = "mpi")]
pub mod run;
#[cfg(feature = "mpi")]
mod wall_sums;

pub use error::DistributedError;
#[cfg(feature = "mpi")]
pub use mpi;
#[cfg(feature = "mpi")]
pub use run::DistributedRun;
