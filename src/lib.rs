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
//! - [`scene`]: the TOML scene format, its builder ([`scene::load_scene`]) and the run loop ([`scene::Simulation`]).
//! - [`io`]: outputs (CSV series, VTK frames, checkpoints, the contact network) and the contact JSON Lines format.
//! - [`host`]: readings of the host that speed reports print (thread CPU time, load average).
//!
//! Units are SI throughout (m, kg, s, N, J). Every vector names its frame: world unless a name says
//! otherwise (`normal1`, `pos12`, `omega_body`).
//!
//! # Example
//! A cube dropped on a floor, from a scene, stepped for 100 steps; the state is read from the world:
//!
//! ```
//! use polydem::scene::parse_scene;
//! use polydem::world::{step, StepScratch};
//!
//! let scene = r#"
//!     [simulation]
//!     gravity = [0.0, 0.0, -9.81]
//!     end_time = 0.1
//!     output_interval = 0.01
//!     steps_per_contact = 50
//!
//!     [[material]]
//!     name = "rock"
//!     density = 2600.0
//!
//!     [[interaction]]
//!     materials = ["rock", "rock"]
//!     law = "linear"
//!     normal_stiffness = 1.0e6
//!     restitution = 0.4
//!     friction = 0.0
//!
//!     [[shape]]
//!     name = "cube"
//!     kind = "box"
//!     half_extents = [0.05, 0.05, 0.05]
//!
//!     [[body]]
//!     name = "cube"
//!     shape = "cube"
//!     material = "rock"
//!     position = [0.0, 0.0, 0.2]
//!
//!     [[wall]]
//!     name = "floor"
//!     material = "rock"
//!     point = [0.0, 0.0, 0.0]
//!     normal = [0.0, 0.0, 1.0]
//! "#;
//! let mut sim = parse_scene(scene, std::path::Path::new("cube.toml"))?;
//! let mut scratch = StepScratch::default();
//! for _ in 0..100 {
//!     let report = step(&sim.params, &mut sim.world, &mut scratch)?;
//!     assert_eq!(report.contacts, 0); // still falling: no contact yet
//! }
//! let cube = sim.world.body(0);
//! let t = sim.world.time();
//! // Free fall from rest: z = z0 − g t²/2 (leapfrog is exact for a constant force, up to round-off).
//! let expected = 0.2 - 0.5 * 9.81 * t * t;
//! assert!((cube.position.z - expected).abs() < 1e-9 * 0.2, "z = {}, expected {expected}", cube.position.z);
//! println!("t = {t:.4} s, z = {:.6} m, v_z = {:.4} m/s", cube.position.z, cube.velocity.z);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A world can also be built by hand ([`world::World`]), a scene loaded from a file and run with its
//! outputs ([`scene::Simulation`]), and two shapes queried directly ([`contact::query_polyhedra`]).

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
