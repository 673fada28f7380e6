//! The paper's experiment (Zhao, Feng et al. 2021, section 4): a graded Voronoi rockfill, packed under gravity
//! and compacted, struck by an ogive-nosed projectile at 1200 m/s.
//!
//! One concept per file:
//! - [`seeds`]: the seed count of eq. 28 and uniform random seeds in a box;
//! - [`voronoi`]: the 3D Voronoi cells of the seeds (voro++ through `voro_rs`);
//! - [`grading`]: eq. 29's shrinking of each cell toward its seed to a graded rock;
//! - [`generation`]: the three above end to end;
//! - [`statistics`]: realised size distribution and shape statistics;
//! - [`projectile`]: the ogive-nosed projectile with its internal cavity (mass properties solid − cavity);
//! - [`materials`]: Table 1's contact parameters and the parameters the paper does not state;
//! - [`packing`]: the container, deposition under gravity, compaction by a moving top wall, hold, bed file;
//! - [`penetration`]: the impact run and its monitors (velocity, resistance, deflection, disturbed zone);
//! - [`cli`]: the `polydem rockfill` subcommand.

pub mod generation;
pub mod grading;
pub mod projectile;
pub mod seeds;
pub mod statistics;
pub mod voronoi;

pub use generation::{generate, GenerationError, GenerationParams, Sample};
