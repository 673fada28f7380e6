//! polydem — a convex-polyhedral discrete element engine.
//!
//! The method follows Zhao, Feng et al. (2021), "Discrete Element Modelling of Dynamic Behaviour of Rockfills
//! for Resisting High Speed Projectile Penetration" (CMES, DOI 10.32604/cmes.2021.015913): contact between
//! convex polyhedra is detected by GJK and measured by EPA as the *Minkowski overlap* (depth δ_M, normal n_M,
//! contact points c1, c2 and c_M = (c1 + c2)/2), which makes an elastic normal law energy-conserving.
//!
//! Modules, one concept each:
//! - [`math`]: the f64 linear-algebra aliases every other module uses.
//! - [`shape`]: convex polyhedra (hull, adjacency, principal frame, mass properties), spheres, planes.
//! - [`contact`]: support mapping, GJK, EPA, the exact SAT oracle, fast paths per shape pair, dispatch.
//! - [`dynamics`]: body state, leapfrog translation, the symplectic splitting rotation (paper eqs. 18–25).
//! - [`law`]: contact laws as pure functions (normal power law, restitution damping, tangential spring).
//! - [`fixed_hash`]: hash maps with a fixed seed (runs and instruction counts that repeat exactly).
//! - [`special_functions`]: elliptic integrals and Jacobi elliptic functions for the analytic references.
//! - [`world`]: the many-body engine: broad phase, contact store, step pipeline.

#![warn(missing_docs)]
#![cfg_attr(doctest, doc = include_str!("../README.md"))] // the README's example is a doctest

pub mod contact;
pub mod dynamics;
pub mod fixed_hash;
pub mod host;
pub mod io;
pub mod law;
pub mod math;
pub mod scene;
pub mod shape;
pub mod special_functions;
pub mod world;
