//! Spheres: the simplest convex shape, with a closed-form support map and mass properties.

use crate::math::{Matrix, Point, Pose, Real, Rotation, Vector};

use super::aabb::Aabb;
use super::error::ShapeError;
use super::mass::MassProperties;
use super::support::SupportMap;

/// A solid sphere of `radius` (m) centred at the origin of its local frame.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sphere {
    radius: Real,
}

impl Sphere {
    /// A sphere of the given radius; the radius must be finite and positive.
    pub fn new(radius: Real) -> Result<Sphere, ShapeError> {
        if !radius.is_finite() || radius <= 0.0 {
            return Err(ShapeError::InvalidParameter {
                name: "radius",
                value: radius.to_string(),
                reason: "must be finite and positive",
            });
        }
        Ok(Sphere { radius })
    }

    /// Radius (m).
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// The characteristic length tolerances are scaled by: the diameter (m).
    pub fn length_scale(&self) -> Real {
        2.0 * self.radius
    }

    /// Mass properties per unit density: V = 4/3 π r³, isotropic inertia 2/5 V r² (m⁵), principal frame =
    /// local frame.
    pub fn mass_properties(&self) -> MassProperties {
        let volume = 4.0 / 3.0 * std::f64::consts::PI * self.radius.powi(3);
        let moment = 0.4 * volume * self.radius * self.radius;
        MassProperties {
            volume,
            centroid: Point::origin(),
            inertia: Matrix::identity() * moment,
            principal_moments: Vector::repeat(moment),
            principal_axes: Rotation::identity(),
        }
    }

    /// World-frame axis-aligned bounding box of the sphere placed at `pose`.
    pub fn aabb(&self, pose: &Pose) -> Aabb {
        let centre = Point::from(pose.translation.vector);
        let r = Vector::repeat(self.radius);
        Aabb {
            mins: centre - r,
            maxs: centre + r,
        }
    }
}

impl SupportMap for Sphere {
    /// The point of the sphere farthest along `dir_local`: `radius · dir/|dir|`. The hint is not used.
    fn local_support(&self, dir_local: &Vector, _hint: &mut u32) -> Point {
        Point::from(dir_local * (self.radius / dir_local.norm()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_non_positive_or_non_finite_radius() {
        for r in [0.0, -1.0, Real::NAN, Real::INFINITY] {
            assert!(Sphere::new(r).is_err(), "radius {r} accepted");
        }
    }

    #[test]
    fn support_point_is_on_the_surface_along_the_direction() {
        let s = Sphere::new(0.25).unwrap();
        let dir = Vector::new(3.0, -4.0, 12.0);
        let p = s.local_support(&dir, &mut 0);
        let expected = dir / 13.0 * 0.25;
        assert!(
            (p.coords - expected).norm() < 1e-16,
            "support {p:?}, expected {expected:?}"
        );
    }

    #[test]
    fn mass_properties_match_closed_form() {
        let r: Real = 0.3;
        let mp = Sphere::new(r).unwrap().mass_properties();
        let v = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
        assert!(
            (mp.volume - v).abs() <= 1e-15 * v,
            "volume {} vs {v}",
            mp.volume
        );
        let i = 2.0 / 5.0 * v * r * r;
        for k in 0..3 {
            assert!(
                (mp.principal_moments[k] - i).abs() <= 1e-15 * i,
                "moment {k}: {} vs {i}",
                mp.principal_moments[k]
            );
        }
    }
}
