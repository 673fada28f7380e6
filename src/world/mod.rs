//! The many-body world: broad phase, contact store, the step pipeline and the energy ledger.
//!
//! - [`broad_phase`]: candidate pairs from bounding spheres in a uniform grid with a Verlet skin.
//! - `grid`: the uniform grid (cell binning, neighbour-cell iteration) of the broad phase and of the flat
//!   sphere layout's neighbour list.
//! - [`world`](mod@world): the plain data of a simulation (bodies, walls, shapes, material-pair laws, kept state).
//! - [`contact_store`]: per-pair state (warm start, tangential history) keyed by the ordered pair.
//! - [`step`](mod@step): one time step, stage by stage, with timers and counters.
//! - [`energy`]: the energy ledger that audits a run.
//! - [`skips`]: the work a scene does not need, each skip switchable.
//! - [`sleeping`]: freezing bodies at rest, islands, waking.
//! - [`parallel`]: deterministic per-item parallelism of the step's stages (rayon).
//! - [`sphere_flat`]: a world of free spheres stepped from flat per-sphere arrays and a half neighbour list.

mod access;
mod body_inputs;
pub mod broad_phase;
pub mod contact_store;
mod distributed;
pub mod energy;
mod energy_share;
mod grid;
mod loads;
mod material_presence;
pub mod parallel;
pub mod region_profile;
mod separation_bound;
pub mod skips;
mod sleep_state;
pub mod sleeping;
pub mod sphere_flat;
pub mod step;
pub mod timing;
pub mod tunnelling;
mod wall;
#[allow(clippy::module_inception)]
pub mod world;

pub use contact_store::{ContactKey, ContactState, ContactStore};
pub use distributed::PartBroadPhase;
pub use energy::{EnergyLedger, EnergyReport};
pub use energy_share::EnergyShare;
pub use parallel::Parallelism;
pub use skips::Skips;
pub use sleeping::{SleepParams, SleepState};
pub use sphere_flat::{NotSphereOnly, SphereSim, StepFlatError};
pub use step::sphere::applies as sphere_step_applies;
pub use step::{
    evaluate_initial_loads, step, RebuildConsensus, RebuildVote, StepCounters, StepError,
    StepParams, StepReport, StepScratch, TimeStepCheck, TimeStepFinding,
};
pub use world::{Loads, MaterialTable, SetupStats, Wall, World, WorldError};
