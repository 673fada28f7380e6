//! Shapes: convex polyhedra, spheres and planes (walls).
//!
//! Every shape is described in its own local frame; a [`Pose`](crate::math::Pose) places it in the world.
//! A polyhedron's local frame is its principal frame (origin at the centroid, axes along the principal axes of
//! inertia), so that the rotation integrator can use the diagonal inertia directly.
//!
//! One job per file: [`error`] (construction errors), `hull` (point cloud → polygonal convex hull),
//! `polygon` (face plane helpers), [`mass`] (exact mass properties), [`polyhedron`] (the polyhedron, its
//! topology and support map), [`aabb`], `support` (the support-map trait).

pub mod aabb;
pub mod error;
mod hull;
pub mod mass;
mod polygon;
pub mod polyhedron;
mod support;

pub use aabb::Aabb;
pub use error::ShapeError;
pub use mass::MassProperties;
pub use polyhedron::ConvexPolyhedron;
pub use support::SupportMap;
