//! Shapes: convex polyhedra, spheres and planes (walls).
//!
//! Every shape is described in its own local frame; a [`Pose`](crate::math::Pose) places it in the world.
//! A polyhedron's local frame is its principal frame (origin at the centroid, axes along the principal axes of
//! inertia), so that the rotation integrator can use the diagonal inertia directly.
//!
//! One job per file: [`error`] (construction errors), `hull` (point cloud → polygonal convex hull),
//! `polygon` (face plane helpers), [`mass`] (exact mass properties), [`polyhedron`] (the polyhedron, its
//! topology and support map), [`sphere`], [`plane`] (walls), [`aabb`], `support` (the support-map trait).

pub mod aabb;
pub mod error;
mod hull;
pub mod mass;
pub mod plane;
mod polygon;
pub mod polyhedron;
pub mod sphere;
mod support;

pub use aabb::Aabb;
pub use error::ShapeError;
pub use mass::MassProperties;
pub use plane::Plane;
pub use polyhedron::ConvexPolyhedron;
pub use sphere::Sphere;
pub use support::SupportMap;

use crate::math::Real;

/// Any shape a body or wall can have. Polyhedra are shared (`Arc`) because many bodies use one shape.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    Polyhedron(std::sync::Arc<ConvexPolyhedron>),
    Sphere(Sphere),
    Plane(Plane),
}

impl Shape {
    /// The characteristic length that tolerances of queries involving this shape are scaled by (m): the
    /// bounding-sphere diameter of a polyhedron, the diameter of a sphere, and `None` for a plane, which is
    /// unbounded (a pair with a plane uses the other shape's length scale).
    pub fn length_scale(&self) -> Option<Real> {
        match self {
            Shape::Polyhedron(p) => Some(p.length_scale()),
            Shape::Sphere(s) => Some(s.length_scale()),
            Shape::Plane(_) => None,
        }
    }
}
