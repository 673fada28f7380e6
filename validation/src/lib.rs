//! polydem-validation: the verification suite behind `cargo validate` and the `cargo test` gates.
//!
//! - [`case`]: the [`Case`] trait, profiles, checks and the TOML case data.
//! - [`cases`]: the registry, one module per case.
//! - [`context`], [`plot`], [`progress`], [`report`], [`provenance`], [`runner`]: the machinery that runs
//!   cases and writes `reports/`.
//! - [`pairsets`]: seeded contact pair sets; [`peers`]: adapters to peer codes (parry3d).
//! - [`perf`]: instruction counts per commit, the regression gate and the dashboard (`cargo perf`).

pub mod case;
pub mod cases;
pub mod check;
pub mod context;
pub mod error;
pub mod gate;
pub mod pairsets;
pub mod peers;
pub mod perf;
pub mod plot;
pub mod progress;
pub mod provenance;
pub mod report;
pub mod runner;
pub mod sim;
pub mod stats;

pub use case::{Case, CaseData, Check, Profile, Target};
pub use error::SuiteError;
pub use runner::{run_case_in_memory, CaseReport};
