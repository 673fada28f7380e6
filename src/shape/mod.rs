//! Shapes: convex polyhedra, spheres and planes (walls).
//!
//! Every shape is described in its own local frame; a [`Pose`](crate::math::Pose) places it in the world.
//! A polyhedron's local frame is its principal frame (origin at the centroid, axes along the principal axes of
//! inertia), so that the rotation integrator can use the diagonal inertia directly.

mod support;

pub use support::SupportMap;
