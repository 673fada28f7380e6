//! Input and output formats of the engine, one format per file.
//!
//! - [`pairs_jsonl`]: the `polydem contact` pair format (JSON Lines in, JSON Lines out).
//! - [`csv_output`]: the CSV time series of `polydem run` (tracked bodies, energy ledger).
//! - [`vtk`]: VTK frames (`.vtu`) and `.pvd` collections of polyhedra, spheres and walls for ParaView.
//! - [`run_summary`]: the run summary of `polydem run` as text and JSON.
//! - [`checkpoint`]: the versioned binary checkpoint of a whole simulation, for restarts.
//! - [`output`]: the [`output::Output`] trait a run's outputs share, and [`output::OutputSet`], the
//!   observer that hands them the state; its implementations: [`csv_series`], [`vtk_frames`],
//!   [`checkpoint_series`], [`contact_network`]; [`output_lock`], one run per output directory;
//!   [`run_identity`], which run a directory and a checkpoint belong to; [`run_outputs`], the outputs of a
//!   run opened the same way by every front door.

pub mod checkpoint;
pub mod checkpoint_series;
pub mod contact_network;
pub mod csv_continue;
pub mod csv_output;
pub mod csv_series;
pub mod output;
pub mod output_lock;
pub mod pairs_jsonl;
pub mod run_identity;
pub mod run_outputs;
pub mod run_summary;
pub mod vtk;
pub mod vtk_frames;
