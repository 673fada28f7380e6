//! Scaling measurements and the cost model built on them (`polydem-mpi-scaling`, behind the `mpi`
//! feature, runs the measurements; these parts need no MPI and are tested without it).
//!
//! - [`scene`]: the generated scenes whose size is a parameter (a lattice of spheres or of polyhedra in
//!   an open box, tiled along x so that a weak-scaling run keeps the bodies per rank fixed).
//! - [`record`]: one CSV row per rank of a measured run, and the per-run figures drawn from them.
//! - [`model`]: the cost of one step on P ranks for N bodies, calibrated on the measured figures and
//!   extrapolated to cluster sizes.
//!
//! Re-running the whole set (about 5 minutes on 2 cores) and regenerating `reports/mpi.md`:
//! `MPI_PKG_CONFIG=mpich cargo run --release -p polydem-mpi --features mpi --bin polydem-mpi-scaling -- drive`

pub mod model;
pub mod record;
pub mod scene;
