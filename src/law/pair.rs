//! The constants of a contact model that depend on the two bodies in contact rather than on their
//! materials alone.
//!
//! Hertz–Mindlin set from material constants (YADE `Ip2_FrictMat_FrictMat_MindlinPhys`, LIGGGHTS
//! `model hertz`) has k_n = (4/3) E* √R* and k_t = 8 G* √(R* δ) with the effective radius
//! R* = R_A R_B/(R_A + R_B) of the pair, or R* = R against a flat wall (as LIGGGHTS; YADE's
//! `Ig2_Wall_Sphere_ScGeom` takes R* = R/2 instead). A material pair therefore stores the law per √m
//! ([`RadiusScaling::SqrtEffectiveRadius`]) and each contact scales it by its own √R*
//! ([`ContactModel::for_shapes`]). The effective mass m* is formed by the step from the two bodies' masses
//! (m_A m_B/(m_A + m_B), the dynamic body's mass against a wall or a fixed body) and enters the damping.
//!
//! The contact radius of a body is its radius for a sphere and, for a polyhedron, the radius of the sphere
//! of equal volume, (3V/4π)^(1/3): Hertz theory has no radius for a polyhedron, and the equal-volume sphere
//! keeps the stiffness of a polyhedral bed comparable with the sphere bed it replaces (the same choice as
//! the equivalent-sphere stiffness of polyhedral DEM codes that borrow sphere laws).

use super::model::ContactModel;
use super::normal::RadiusScaling;
use super::tangential::TangentialLaw;
use crate::math::Real;
use crate::shape::Shape;

/// The contact radius of a shape (m): a sphere's radius; the equal-volume radius of a polyhedron (and of any
/// other bounded shape); `None`
/// for a plane (a wall: R* = R of the other body).
pub fn contact_radius(shape: &Shape) -> Option<Real> {
    match shape {
        Shape::Sphere(s) => Some(s.radius()),
        Shape::Polyhedron(p) => {
            let volume = p.mass_properties().volume;
            Some((3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt())
        }
        Shape::Plane(_) => None,
        other => other.convex().map(|c| {
            let volume = c.mass_properties().volume;
            (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt()
        }),
    }
}

/// R* of a pair: R_A R_B/(R_A + R_B), or the body's own radius against a wall (`a` is `None` or a plane).
pub fn effective_radius(a: Option<&Shape>, b: &Shape) -> Real {
    effective_contact_radius(a.and_then(contact_radius), contact_radius(b))
}

/// R* from the contact radii of the two sides (`None` for a wall): R_A R_B/(R_A + R_B), or the one radius.
#[inline]
pub fn effective_contact_radius(ra: Option<Real>, rb: Option<Real>) -> Real {
    match (ra, rb) {
        (Some(ra), Some(rb)) => ra * rb / (ra + rb),
        (None, Some(r)) | (Some(r), None) => r,
        (None, None) => Real::INFINITY,
    }
}

impl ContactModel {
    /// The model of one contact between shape `a` (`None` for a wall) and shape `b`: the model itself when
    /// its stiffnesses are constants, otherwise k_n and the tangential stiffness multiplied by √R*.
    #[inline]
    pub fn for_shapes(&self, a: Option<&Shape>, b: &Shape) -> ContactModel {
        match self.normal.radius_scaling {
            RadiusScaling::Constant => *self,
            RadiusScaling::SqrtEffectiveRadius => {
                self.with_root_radius(effective_radius(a, b).sqrt())
            }
        }
    }

    /// [`ContactModel::for_shapes`] from the contact radii of the two sides ([`contact_radius`]; `None` for
    /// a wall): the same model, without looking at the shapes.
    #[inline]
    pub fn for_contact_radii(&self, ra: Option<Real>, rb: Option<Real>) -> ContactModel {
        match self.normal.radius_scaling {
            RadiusScaling::Constant => *self,
            RadiusScaling::SqrtEffectiveRadius => {
                self.with_root_radius(effective_contact_radius(ra, rb).sqrt())
            }
        }
    }

    /// The model of one contact whose √R* is `root_radius`: the model itself when its stiffnesses are
    /// constants, otherwise [`ContactModel::with_root_radius`].
    #[inline]
    pub fn for_root_radius(&self, root_radius: Real) -> ContactModel {
        if self.normal.scales_with_radius() {
            self.with_root_radius(root_radius)
        } else {
            *self
        }
    }

    /// k_n and the tangential stiffness multiplied by `root_radius` = √R*; the result has constant
    /// stiffnesses.
    #[inline]
    pub fn with_root_radius(&self, root_radius: Real) -> ContactModel {
        let mut model = *self;
        model.normal.stiffness *= root_radius;
        model.normal.radius_scaling = RadiusScaling::Constant;
        model.tangential = match self.tangential {
            TangentialLaw::None => TangentialLaw::None,
            TangentialLaw::Spring {
                stiffness,
                friction,
                rotation,
            } => TangentialLaw::Spring {
                stiffness: stiffness * root_radius,
                friction,
                rotation,
            },
            TangentialLaw::Mindlin {
                coefficient,
                friction,
                rotation,
            } => TangentialLaw::Mindlin {
                coefficient: coefficient * root_radius,
                friction,
                rotation,
            },
            TangentialLaw::DampedMindlin {
                coefficient,
                friction,
                damping,
                rotation,
            } => TangentialLaw::DampedMindlin {
                coefficient: coefficient * root_radius,
                friction,
                damping,
                rotation,
            },
        };
        model
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::hertz_mindlin::{hertz_mindlin, ElasticMaterial, SpherePair};
    use crate::law::hertz_mindlin::{material_hertz_mindlin, HertzMindlinOptions};
    use crate::math::{Point, Vector};
    use crate::shape::{ConvexPolyhedron, Plane, Sphere};

    #[test]
    fn scaled_model_equals_the_model_built_for_the_two_radii() {
        let bed = ElasticMaterial::new(1e9, 0.2).unwrap();
        let steel = ElasticMaterial::new(210e9, 0.3).unwrap();
        let options = HertzMindlinOptions {
            tangential_damping: false,
            limit_force: false,
        };
        let per_root = material_hertz_mindlin(&bed, &steel, 0.4, 0.2, options).unwrap();
        let (ra, rb) = (2.1e-3, 5e-3);
        let a = Shape::Sphere(Sphere::new(ra).unwrap());
        let b = Shape::Sphere(Sphere::new(rb).unwrap());
        let direct = hertz_mindlin(&SpherePair {
            material_a: bed,
            material_b: steel,
            radius_a: ra,
            radius_b: Some(rb),
            restitution: 0.4,
            friction: 0.2,
        })
        .unwrap();
        let scaled = per_root.for_shapes(Some(&a), &b);
        let rel = |x: Real, y: Real| (x - y).abs() / y.abs();
        assert!(
            rel(scaled.normal.stiffness, direct.normal.stiffness) < 1e-14,
            "k_n scaled {} vs built for R_a = {ra}, R_b = {rb}: {}",
            scaled.normal.stiffness,
            direct.normal.stiffness
        );
        let (kt_s, _) = scaled.tangential.stiffness_and_friction(1e-5);
        let (kt_d, _) = direct.tangential.stiffness_and_friction(1e-5);
        assert!(
            rel(kt_s, kt_d) < 1e-14,
            "k_t scaled {kt_s} vs direct {kt_d}"
        );
        // Against a wall: R* = R (LIGGGHTS convention).
        let wall = Shape::Plane(Plane::new(Vector::z(), 0.0).unwrap());
        let on_wall = per_root.for_shapes(Some(&wall), &a);
        assert!(
            rel(
                on_wall.normal.stiffness,
                per_root.normal.stiffness * ra.sqrt()
            ) < 1e-15,
            "wall contact k_n {}, expected (4/3)E*√R",
            on_wall.normal.stiffness
        );
        assert_eq!(per_root.for_shapes(None, &a), on_wall);
    }

    /// The model for a √R* is the one for the two radii, bit for bit, whether or not the law scales.
    #[test]
    fn model_for_a_root_radius_is_the_model_for_the_radii() {
        let bed = ElasticMaterial::new(1e9, 0.2).unwrap();
        let options = HertzMindlinOptions {
            tangential_damping: true,
            limit_force: false,
        };
        let scaling = material_hertz_mindlin(&bed, &bed, 0.4, 0.2, options).unwrap();
        let constant = ContactModel {
            normal: crate::law::NormalLaw::hertz(1e8).unwrap(),
            damping: crate::law::DampingLaw::None,
            tangential: TangentialLaw::spring(1e5, 0.3).unwrap(),
        };
        for model in [scaling, constant] {
            for (ra, rb) in [(Some(2.1e-3), Some(5e-3)), (None, Some(1e-3))] {
                let root = effective_contact_radius(ra, rb).sqrt();
                assert_eq!(
                    model.for_root_radius(root),
                    model.for_contact_radii(ra, rb),
                    "model {model:?}, radii {ra:?} {rb:?}"
                );
            }
        }
        assert_eq!(constant.for_root_radius(0.5), constant);
    }

    #[test]
    fn polyhedron_contact_radius_is_the_equal_volume_radius() {
        let h = 0.5e-3;
        let corners: Vec<Point> = (0..8)
            .map(|i| {
                let s = |bit: usize| if i & (1 << bit) != 0 { h } else { -h };
                Point::new(s(0), s(1), s(2))
            })
            .collect();
        let (cube, _) = ConvexPolyhedron::from_points(&corners).unwrap();
        let r = contact_radius(&Shape::Polyhedron(std::sync::Arc::new(cube))).unwrap();
        let expected = (3.0 * (2.0 * h as Real).powi(3) / (4.0 * std::f64::consts::PI)).cbrt();
        assert!(
            (r - expected).abs() < 1e-12 * expected,
            "cube of side {} m: contact radius {r}, equal-volume radius {expected}",
            2.0 * h
        );
    }
}
