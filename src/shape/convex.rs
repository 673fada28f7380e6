//! The convex-shape seam: everything the engine needs from a bounded convex body, in its body frame.
//!
//! A shape that implements [`ConvexShape`] goes through the generic support-map arm of the narrow phase
//! (GJK and EPA, `crate::contact::contact_support_map`), the broad phase (its bounding radius), the mass
//! set-up (its mass properties per unit density), the tunnelling monitor ([`ConvexShape::segment_enters`])
//! and the VTK surface series ([`ConvexShape::surface_mesh`]) without a special case elsewhere. Special pair
//! paths (sphere–sphere, polyhedron–plane, …) are optional speed-ups.
//!
//! The body frame is the principal frame: origin at the centroid, axes along the principal axes of inertia,
//! so that [`MassProperties::principal_moments`] is the diagonal inertia the integrator uses.

use crate::math::{Point, Pose, Real, Vector};

use super::aabb::Aabb;
use super::mass::MassProperties;
use super::polyhedron::ConvexPolyhedron;
use super::sphere::Sphere;
use super::support::SupportMap;
use super::surface_mesh::uv_surface;
pub use super::surface_mesh::SurfaceMesh;

/// A bounded convex solid described in its body (principal) frame.
pub trait ConvexShape: SupportMap + Send + Sync + std::fmt::Debug {
    /// Radius of the smallest origin-centred sphere containing the solid (m): the broad phase's reach.
    fn bounding_radius(&self) -> Real;

    /// The characteristic length that tolerances are scaled by: the bounding-sphere diameter (m).
    fn length_scale(&self) -> Real {
        2.0 * self.bounding_radius()
    }

    /// Volume, centroid (the origin) and principal inertia per unit density (m³, m, m⁵).
    fn mass_properties(&self) -> MassProperties;

    /// World-frame axis-aligned bounding box of the solid placed at `pose`.
    fn aabb(&self, pose: &Pose) -> Aabb;

    /// Whether the segment `p0 → p1` (body frame) meets the solid while `p0` is outside it.
    fn segment_enters(&self, p0: &Point, p1: &Point) -> bool;

    /// The surface drawn in the VTK output (body frame). Exact for polyhedra, a documented tessellation
    /// for curved shapes.
    fn surface_mesh(&self) -> SurfaceMesh;
}

/// Distance from the origin to the segment `p0 → p1` (m).
pub fn segment_distance_to_origin(p0: &Point, p1: &Point) -> Real {
    let d: Vector = p1 - p0;
    let len2 = d.norm_squared();
    let t = if len2 > 0.0 {
        (-p0.coords.dot(&d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p0.coords + t * d).norm()
}

impl ConvexShape for Sphere {
    fn bounding_radius(&self) -> Real {
        self.radius()
    }

    fn length_scale(&self) -> Real {
        Sphere::length_scale(self)
    }

    fn mass_properties(&self) -> MassProperties {
        Sphere::mass_properties(self)
    }

    fn aabb(&self, pose: &Pose) -> Aabb {
        Sphere::aabb(self, pose)
    }

    fn segment_enters(&self, p0: &Point, p1: &Point) -> bool {
        let r = self.radius();
        if p0.coords.norm() <= r {
            return false;
        }
        segment_distance_to_origin(p0, p1) <= r
    }

    fn surface_mesh(&self) -> SurfaceMesh {
        let r = self.radius();
        uv_surface(r, r, r)
    }
}

impl ConvexShape for ConvexPolyhedron {
    fn bounding_radius(&self) -> Real {
        ConvexPolyhedron::bounding_radius(self)
    }

    fn length_scale(&self) -> Real {
        ConvexPolyhedron::length_scale(self)
    }

    fn mass_properties(&self) -> MassProperties {
        ConvexPolyhedron::mass_properties(self).clone()
    }

    fn aabb(&self, pose: &Pose) -> Aabb {
        ConvexPolyhedron::aabb(self, pose)
    }

    /// Clips the segment's parameter interval against every face plane (Cyrus–Beck).
    fn segment_enters(&self, p0: &Point, p1: &Point) -> bool {
        let d = p1 - p0;
        let (mut t_in, mut t_out): (Real, Real) = (0.0, 1.0);
        let mut start_inside = true;
        for f in 0..self.num_faces() {
            let n = self.face_normal(f);
            let slack = self.face_offset(f) - n.dot(&p0.coords);
            if slack < 0.0 {
                start_inside = false;
            }
            let rate = n.dot(&d);
            if rate == 0.0 {
                if slack < 0.0 {
                    return false;
                }
            } else if rate < 0.0 {
                t_in = t_in.max(slack / rate);
            } else {
                t_out = t_out.min(slack / rate);
            }
            if t_in > t_out {
                return false;
            }
        }
        !start_inside
    }

    fn surface_mesh(&self) -> SurfaceMesh {
        SurfaceMesh {
            vertices: self.vertices().to_vec(),
            faces: (0..self.num_faces())
                .map(|f| self.face_vertices(f).to_vec())
                .collect(),
        }
    }
}
