//! The many-body world: broad phase, contact store and the step pipeline.

pub mod broad_phase;
