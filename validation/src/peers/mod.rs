//! Peer codes the suite compares against, behind adapters that speak polydem's types.
//!
//! - [`parry`]: parry3d-f64 0.31 (GJK/EPA contact, intersection test, distance) on convex polyhedra.
//! - [`native`]: libccd 2.1 and Bullet 3.24 through C/C++ shims (feature `peers`).
//! - [`rapier`]: rapier3d-f64 0.36's rigid-body integrator on a single free body (precession case).
//!
//! Every nalgebra ↔ glam conversion lives in [`polydem::math::glam`] (one place, project rule).

pub mod native;
pub mod parry;
pub mod rapier;
