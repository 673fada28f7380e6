//! Input and output formats of the engine, one format per file.
//!
//! - [`pairs_jsonl`]: the `polydem contact` pair format (JSON Lines in, JSON Lines out).
//! - [`csv_output`]: the CSV time series of `polydem run` (tracked bodies, energy ledger).
//! - [`vtk`]: VTK frames (`.vtu`) and `.pvd` collections of polyhedra, spheres and walls for ParaView.
//! - [`run_summary`]: the run summary of `polydem run` as text and JSON.
//! - [`checkpoint`]: the versioned binary checkpoint of a whole simulation, for restarts.

pub mod checkpoint;
pub mod csv_continue;
pub mod csv_output;
pub mod pairs_jsonl;
pub mod run_summary;
pub mod vtk;
