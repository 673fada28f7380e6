//! The paper's experiment (Zhao, Feng et al. 2021, section 4): a graded Voronoi rockfill, packed under gravity
//! and compacted, struck by an ogive-nosed projectile at 1200 m/s.
//!
//! One concept per file:
//! - [`seeds`]: the seed count of eq. 28 and uniform random seeds in a box;
//! - [`voronoi`]: the 3D Voronoi cells of the seeds (voro++ through `voro_rs`);
//! - [`grading`]: eq. 29's shrinking of each cell toward its seed to a graded rock;
//! - [`spatial_order`]: the rocks numbered along a Z-order curve of their centres (memory locality);
//! - [`generation`]: the above end to end;
//! - [`statistics`]: realised size distribution and shape statistics;
//! - [`projectile`]: the ogive-nosed projectile with its internal cavity (mass properties solid − cavity);
//! - [`config`]: the experiment's parameters as data (Table 1 and what the paper does not state), the laws;
//! - [`limits`]: the most rocks and steps a run may take, checked before the work starts;
//! - [`collapse`]: the geometric pre-collapse of the loose sample (rocks moved straight down until nearly
//!   supported) that the packing starts from;
//! - [`packing`]: the container, deposition under gravity, compaction by a moving top wall, hold, bed CSV;
//! - [`bed`]: the packed bed as an engine checkpoint, so that penetration runs start from it;
//! - [`monitors`]: the projectile's monitor series (`monitors.csv`) as an engine output;
//! - [`penetration`]: the impact run (velocity, resistance, deflection, disturbed zone) and its files;
//! - [`stepper`]: who takes the impact's steps: this process, or the ranks of an MPI job
//!   (`distributed`, feature `mpi`);
//! - [`experiment`]: generation → packing (or a saved bed) → penetration;
//! - [`stop`]: the check a front end answers to stop a packing or penetration run between two steps;
//! - [`cli`]: the `polydem rockfill` subcommand.

pub mod bed;
pub mod cli;
pub mod collapse;
pub mod config;
pub mod convergence;
#[cfg(feature = "mpi")]
pub mod distributed;
pub mod experiment;
pub mod generation;
pub mod grading;
pub mod limits;
pub mod monitors;
pub mod packing;
pub mod packing_run;
pub mod penetration;
mod penetration_error;
pub mod projectile;
pub mod section;
pub mod seeds;
pub mod sensitivity;
pub mod spatial_order;
pub mod statistics;
pub mod stepper;
pub mod stop;
pub mod study;
pub mod summary;
pub mod voronoi;

pub use generation::{generate, GenerationError, GenerationParams, Sample};
