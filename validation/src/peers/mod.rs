//! Peer codes the suite compares against, behind adapters that speak polydem's types.
//!
//! - [`parry`]: parry3d-f64 0.31 (GJK/EPA contact, intersection test, distance) on convex polyhedra.
//! - [`rapier`]: rapier3d-f64 0.36's rigid-body integrator on a single free body (precession case).
//! - [`convert`]: every nalgebra ↔ glam conversion of the harness (one file, project rule).

pub mod convert;
pub mod parry;
pub mod rapier;
