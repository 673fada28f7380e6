//! Contact geometry between convex shapes: the Minkowski contact features of the paper (section 2.1).
//!
//! The narrow phase answers one question per pair — where and how much do these two shapes overlap — and
//! returns a [`ContactGeometry`]. It never computes forces: contact laws live elsewhere and consume the
//! geometry.

mod geometry;

pub use geometry::{ContactGeometry, ContactKind, SolverStatus};
