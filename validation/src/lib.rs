//! polydem-validation: the verification suite behind `cargo validate` and the `cargo test` gates.
