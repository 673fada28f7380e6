//! Ellipsoids: the solid {x : (x/a)² + (y/b)² + (z/c)² ≤ 1} with semi-axes (a, b, c) along the body axes.
//!
//! With D = diag(a, b, c) the ellipsoid is the image D·B of the unit ball B, so every query reduces to the
//! ball's:
//! - support function h(d) = |D d| and support point s(d) = D² d / |D d| (the unit ball's support D d/|D d|
//!   mapped by D);
//! - volume 4/3 π a b c and principal inertia per unit density V/5 (b² + c², a² + c², a² + b²), the body
//!   frame being the principal frame (a uniform ellipsoid's centroid is its centre, its axes are principal);
//! - bounding radius max(a, b, c); world AABB half-extent along axis e_i: h(Rᵀ e_i) = |D Rᵀ e_i|;
//! - segment test: the segment mapped by D⁻¹ against the unit ball.
//!
//! The VTK surface is a UV tessellation ([`super::surface_mesh::uv_surface`]) with its vertices on the exact surface.

use crate::math::{Matrix, Point, Pose, Real, Rotation, Vector};

use super::aabb::Aabb;
use super::convex::{segment_distance_to_origin, ConvexShape};
use super::error::ShapeError;
use super::mass::MassProperties;
use super::support::SupportMap;
use super::surface_mesh::{uv_surface, SurfaceMesh};

/// A solid ellipsoid centred at the origin of its body frame with semi-axes `(a, b, c)` (m) along x, y, z.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ellipsoid {
    semi_axes: Vector,
}

impl Ellipsoid {
    /// The ellipsoid with semi-axes `a`, `b`, `c` along the body x, y, z axes; each must be finite and
    /// positive.
    pub fn new(a: Real, b: Real, c: Real) -> Result<Ellipsoid, ShapeError> {
        for (name, value) in [("semi-axis a", a), ("semi-axis b", b), ("semi-axis c", c)] {
            if !value.is_finite() || value <= 0.0 {
                return Err(ShapeError::InvalidParameter {
                    name,
                    value: value.to_string(),
                    reason: "must be finite and positive",
                });
            }
        }
        Ok(Ellipsoid {
            semi_axes: Vector::new(a, b, c),
        })
    }

    /// Semi-axes (a, b, c) (m).
    pub fn semi_axes(&self) -> Vector {
        self.semi_axes
    }

    /// The support function h(d) = max over x in the solid of d·x = |D d| (m times |d|).
    pub fn support_function(&self, dir: &Vector) -> Real {
        dir.component_mul(&self.semi_axes).norm()
    }
}

impl SupportMap for Ellipsoid {
    /// s(d) = D² d / |D d|. The direction is first scaled by its largest component so that |D d| neither
    /// overflows nor underflows for any finite nonzero `dir_local`. The hint is not used.
    #[inline]
    fn local_support(&self, dir_local: &Vector, _hint: &mut u32) -> Point {
        let d = dir_local / dir_local.amax();
        let dd = d.component_mul(&self.semi_axes);
        Point::from(dd.component_mul(&self.semi_axes) / dd.norm())
    }
}

impl ConvexShape for Ellipsoid {
    fn bounding_radius(&self) -> Real {
        self.semi_axes.max()
    }

    fn mass_properties(&self) -> MassProperties {
        let [a, b, c] = [self.semi_axes.x, self.semi_axes.y, self.semi_axes.z];
        let volume = 4.0 / 3.0 * std::f64::consts::PI * a * b * c;
        let moments = Vector::new(b * b + c * c, a * a + c * c, a * a + b * b) * (volume / 5.0);
        MassProperties {
            volume,
            centroid: Point::origin(),
            inertia: Matrix::from_diagonal(&moments),
            principal_moments: moments,
            principal_axes: Rotation::identity(),
        }
    }

    fn aabb(&self, pose: &Pose) -> Aabb {
        let r = pose.rotation.to_rotation_matrix().into_inner();
        let half = Vector::from_fn(|i, _| {
            (0..3)
                .map(|j| (r[(i, j)] * self.semi_axes[j]).powi(2))
                .sum::<Real>()
                .sqrt()
        });
        let centre = Point::from(pose.translation.vector);
        Aabb {
            mins: centre - half,
            maxs: centre + half,
        }
    }

    fn segment_enters(&self, p0: &Point, p1: &Point) -> bool {
        let q0 = Point::from(p0.coords.component_div(&self.semi_axes));
        let q1 = Point::from(p1.coords.component_div(&self.semi_axes));
        q0.coords.norm() > 1.0 && segment_distance_to_origin(&q0, &q1) <= 1.0
    }

    fn surface_mesh(&self) -> SurfaceMesh {
        uv_surface(self.semi_axes.x, self.semi_axes.y, self.semi_axes.z)
    }
}
