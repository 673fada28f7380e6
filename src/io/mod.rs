//! Input and output formats of the engine, one format per file.
//!
//! - [`pairs_jsonl`]: the `polydem contact` pair format (JSON Lines in, JSON Lines out).

pub mod pairs_jsonl;
