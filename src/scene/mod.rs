//! Scene files: a TOML description of a simulation (materials, contact laws, shapes, bodies, walls, time
//! stepping and output), read into typed structs ([`schema`]), validated, and built into a ready-to-run
//! [`Simulation`] ([`build`]). The time step is derived from the shortest contact time unless given, and a
//! given one above the stability limit is refused ([`time_step`]). The format is documented for users in
//! `docs/scene-format.md`.
//!
//! Every error names the file, the line and the field ([`SceneError`]); reading a scene never panics.

pub mod body_file;
pub mod build;
pub mod orientation;
pub mod run;
pub mod run_length;
pub mod schema;
pub mod simulation;
pub mod time_step;

pub use build::{load_scene, parse_scene, SceneError};
pub use run::{EndTimeError, RunError, RunObserver, RunSummary, StepPath, PROGRESS_STEPS};
pub use run_length::{step_count, StepCountError, DEFAULT_MAX_STEPS};
pub use simulation::Simulation;
pub use time_step::TimeStepInfo;
