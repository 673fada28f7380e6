//! polydem over MPI: one world split over processes, bitwise equal to one process for any rank count.
//!
//! # Design
//! - **Where the code lives.** This crate holds the decomposition, the exchanges and the distributed step;
//!   the engine offers three seams (`polydem::world`): [`World::part`](polydem::world::World::part) cuts a
//!   world down to some bodies, [`World::copy_body_from_owner`](polydem::world::World::copy_body_from_owner)
//!   writes a ghost's state and loads, and a [`RebuildConsensus`](polydem::world::RebuildConsensus) set on
//!   the step's scratch takes the broad-phase rebuild decision. A run without MPI takes none of them.
//! - **Subdomains** ([`decomposition`]): recursive coordinate bisection balanced by body count.
//! - **Parts** ([`plan`]): a rank steps the bodies it owns and ghosts within the reach of a candidate pair
//!   plus twice the move a body may make between rebuilds, numbered in global order. The engine sums a
//!   body's forces over its pairs in key order (lower partners by increasing index, higher ones, walls) and
//!   integrates one body at a time, so an owned body gets the bits it gets in one process.
//! - **Ghosts** are stepped with the rest of the part, then overwritten after each step by their owners'
//!   states and loads: the next step's first kick and drift of a ghost then repeat its owner's exactly, so
//!   every pair with an owned body is evaluated on the state one process has. Walls are on every rank.
//! - **Rebuilds** are agreed ([`consensus`]): the two largest moves of the whole world decide, as in one
//!   process. After a rebuild the parts are cut again (migration) with the contact entries (tangential
//!   springs, solver caches) taken from the rank that owns the pair's lower body.
//!
//! # Building and testing
//! `cargo test --release -p polydem-mpi --features mpi` with `MPI_PKG_CONFIG=mpich` (rsmpi then links
//! Debian's MPICH even where `mpicc` points at Open MPI); `tests/mpi_bits.rs` launches itself with
//! `mpirun.mpich -n 1..4` and compares every body's state with one process's, bit for bit. `.ci/mpi.sh`
//! installs the packages and runs it. Without the feature the crate builds its MPI-free parts only
//! (decomposition, plan), so the workspace needs no MPI.
//!
//! # Limits of this stage
//! - A cut gathers the whole state on every rank (O(N) memory and traffic per rebuild); the per-step ghost
//!   exchange is point to point in content (one all-to-all).
//! - The time-step check, sleeping, and the energy ledger's sums are not distributed (the ledger of a part
//!   counts its ghosts' contacts).
//! - A rank whose step fails returns the error; the caller must abort the communicator (the others wait in
//!   the next collective).

pub mod decomposition;
pub mod error;
pub mod plan;
pub mod scaling;

#[cfg(feature = "mpi")]
pub mod consensus;
#[cfg(feature = "mpi")]
pub mod exchange;
#[cfg(feature = "mpi")]
pub mod run;

pub use error::DistributedError;
#[cfg(feature = "mpi")]
pub use mpi;
#[cfg(feature = "mpi")]
pub use run::DistributedRun;
