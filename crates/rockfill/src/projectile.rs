//! The projectile of paper section 4.2: an axisymmetric ogive-nosed body, H = 800 mm long, diameter
//! D = 150 mm, tangent-ogive nose of radius R = 500 mm, discretised as one convex polyhedron with 12 divisions
//! along the head and 36 around the axis, with an internal cavity that changes its mass and inertia.
//!
//! # Geometry (input frame: axis along +x, base at x = 0, tip at x = H)
//! The tangent ogive meets the cylinder without a kink: its arc has radius R and centre at
//! (x_s, −(R − D/2)) in the (x, r) half-plane, with the shoulder at x_s = H − L_n and the nose length
//! L_n = √(R² − (R − D/2)²) (263.4 mm for the paper's values). The 12 head divisions are equal steps of the
//! arc angle φ ∈ [0, asin(L_n/R)] (x = x_s + R sin φ, r = R cos φ − (R − D/2)), which places more rings near
//! the tip than equal steps in x; each ring has 36 vertices on the circle of radius r (an inscribed polygon),
//! plus the base ring at x = 0 and the tip point. The polyhedron is their convex hull.
//!
//! # Cavity (the paper does not give it)
//! A coaxial 36-gon prism (the same angular positions as the hull) of circumradius D/2 − t, t the wall
//! thickness, **centred on the solid hull's centroid** along the axis and as long as fits between the base plate
//! (thickness `base_thickness`) and the shoulder (the nose stays solid). Centring is a constraint of the
//! engine, not a design choice: a body's shape is stored with its origin at the solid hull's centroid and that
//! point is integrated as the centre of mass, so a cavity off the centroid would shift the true centre of mass
//! away from the integrated one. Defaults: t = 20 mm (a wall of 0.13 D, between the thin walls of
//! high-explosive shells, ~0.08 D, and the thick walls of penetrators, ~0.2 D), base plate 30 mm, steel
//! 7850 kg/m³, an empty cavity (fill density 0; set it to ~1700 kg/m³ for a cast explosive fill). With these
//! the projectile weighs about 62 kg (solid: 93 kg).
//!
//! # Mass properties
//! Exact for the polyhedral geometry: solid hull minus cavity prism (both by the divergence-theorem sums of
//! `shape::mass`), combined about the common centre of mass with the parallel-axis theorem:
//! m = ρ V_s − (ρ − ρ_f) V_c, I = ρ I_s − (ρ − ρ_f)(I_c + V_c (|d|² 𝟙 − d dᵀ)), d the cavity centroid's offset
//! (zero up to round-off here).

use std::sync::Arc;

use polydem::dynamics::{BodyError, PrincipalInertia};
use polydem::math::{Matrix, Point, Pose, Real, Rotation, Vector};
use polydem::shape::mass::{polyhedron_mass_properties, MassProperties};
use polydem::shape::{ConvexPolyhedron, ShapeError};

/// Why a projectile could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProjectileError {
    #[error("projectile parameter {name} = {value} is invalid: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: Real,
        reason: &'static str,
    },
    #[error("projectile hull: {0}")]
    Shape(#[from] ShapeError),
    #[error("projectile mass properties: {0}")]
    Body(#[from] BodyError),
    #[error("the hollow body's inertia is not diagonal in the hull's principal frame (off-diagonal/diagonal = {ratio:e})")]
    NotPrincipal { ratio: Real },
}

/// Parameters of the projectile (SI units). [`ProjectileParams::paper`] gives the paper's values and the
/// documented defaults for what the paper does not state.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectileParams {
    /// Overall length H (m).
    pub length: Real,
    /// Ogive radius R (m).
    pub ogive_radius: Real,
    /// Diameter D (m).
    pub diameter: Real,
    /// Divisions of the ogive arc.
    pub head_divisions: usize,
    /// Divisions around the axis.
    pub circumferential_divisions: usize,
    /// Wall thickness of the cavity t (m).
    pub wall_thickness: Real,
    /// Thickness of the base plate behind the cavity (m).
    pub base_thickness: Real,
    /// Density of the casing (kg/m³).
    pub density: Real,
    /// Density of the cavity's fill (kg/m³; 0 for an empty cavity).
    pub fill_density: Real,
}

impl ProjectileParams {
    /// H = 0.8 m, R = 0.5 m, D = 0.15 m, 12 × 36 divisions (paper section 4.2); cavity and steel as in the
    /// module docs.
    pub fn paper() -> Self {
        Self {
            length: 0.8,
            ogive_radius: 0.5,
            diameter: 0.15,
            head_divisions: 12,
            circumferential_divisions: 36,
            wall_thickness: 0.02,
            base_thickness: 0.03,
            density: 7850.0,
            fill_density: 0.0,
        }
    }

    /// Nose length L_n = √(R² − (R − D/2)²) (m).
    pub fn nose_length(&self) -> Real {
        let a = self.ogive_radius - 0.5 * self.diameter;
        (self.ogive_radius.powi(2) - a * a).sqrt()
    }

    /// The (x, r) profile of the head rings, shoulder first, tip (r = 0) last; x along the axis from the base.
    pub fn head_profile(&self) -> Vec<(Real, Real)> {
        let (big_r, half_d) = (self.ogive_radius, 0.5 * self.diameter);
        let nose = self.nose_length();
        let shoulder = self.length - nose;
        let phi_max = (nose / big_r).asin();
        (0..=self.head_divisions)
            .map(|k| {
                if k == self.head_divisions {
                    return (self.length, 0.0);
                }
                let phi = phi_max * k as Real / self.head_divisions as Real;
                (
                    shoulder + big_r * phi.sin(),
                    big_r * phi.cos() - (big_r - half_d),
                )
            })
            .collect()
    }

    fn validate(&self) -> Result<(), ProjectileError> {
        let bad = |name, value, reason| {
            Err(ProjectileError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let positive = [
            ("length", self.length),
            ("ogive_radius", self.ogive_radius),
            ("diameter", self.diameter),
            ("wall_thickness", self.wall_thickness),
            ("base_thickness", self.base_thickness),
            ("density", self.density),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return bad(name, value, "must be finite and positive");
            }
        }
        if !(self.fill_density.is_finite()
            && self.fill_density >= 0.0
            && self.fill_density < self.density)
        {
            return bad("fill_density", self.fill_density, "must be in [0, density)");
        }
        if self.ogive_radius < 0.5 * self.diameter {
            return bad(
                "ogive_radius",
                self.ogive_radius,
                "must be at least D/2 for a tangent ogive",
            );
        }
        if self.nose_length() >= self.length {
            return bad("length", self.length, "must exceed the nose length");
        }
        if self.head_divisions < 1 {
            return bad("head_divisions", 0.0, "must be at least 1");
        }
        if self.circumferential_divisions < 3 {
            return bad(
                "circumferential_divisions",
                self.circumferential_divisions as Real,
                "must be at least 3",
            );
        }
        if self.wall_thickness >= 0.5 * self.diameter {
            return bad("wall_thickness", self.wall_thickness, "must be below D/2");
        }
        Ok(())
    }
}

/// The vertices of a regular `n`-gon prism of circumradius `radius` along x from `x0` to `x1`, and its faces
/// oriented outward (the first vertex of each ring at angle 0 about x, measured from +y toward +z).
pub fn prism(n: usize, radius: Real, x0: Real, x1: Real) -> (Vec<Point>, Vec<Vec<u32>>) {
    let ring = |x: Real| {
        (0..n).map(move |k| {
            let t = 2.0 * std::f64::consts::PI * k as Real / n as Real;
            Point::new(x, radius * t.cos(), radius * t.sin())
        })
    };
    let vertices: Vec<Point> = ring(x0).chain(ring(x1)).collect();
    let n32 = n as u32;
    // Seen from −x the ring at x0 runs clockwise (y toward z is counter-clockwise seen from +x), so the cap at
    // x0 lists the ring backwards and the cap at x1 forwards.
    let mut faces = vec![
        (0..n32).rev().collect::<Vec<u32>>(),
        (n32..2 * n32).collect(),
    ];
    for k in 0..n32 {
        let k1 = (k + 1) % n32;
        faces.push(vec![k, k1, n32 + k1, n32 + k]);
    }
    (vertices, faces)
}

/// Mass, centre of mass and inertia tensor (kg·m², about the centre of mass) of a solid of density `density`
/// with a cavity filled at `fill_density`, both given per unit density in the same frame.
pub fn hollow_mass_properties(
    solid: &MassProperties,
    cavity: &MassProperties,
    density: Real,
    fill_density: Real,
) -> (Real, Point, Matrix) {
    let removed = density - fill_density;
    let mass = density * solid.volume - removed * cavity.volume;
    let com = Point::from(
        (solid.centroid.coords * density * solid.volume
            - cavity.centroid.coords * removed * cavity.volume)
            / mass,
    );
    let shift = |d: Vector, volume: Real| {
        (Matrix::identity() * d.norm_squared() - d * d.transpose()) * volume
    };
    let inertia = (solid.inertia + shift(solid.centroid - com, solid.volume)) * density
        - (cavity.inertia + shift(cavity.centroid - com, cavity.volume)) * removed;
    (mass, com, inertia)
}

/// The projectile as the engine needs it.
#[derive(Clone, Debug)]
pub struct Projectile {
    pub params: ProjectileParams,
    /// The outer hull in its principal frame.
    pub shape: Arc<ConvexPolyhedron>,
    /// Principal frame → input frame (axis +x, base at x = 0).
    pub input_from_body: Pose,
    /// Mass of the hollow body (kg) and of the solid hull at the same density (kg).
    pub mass: Real,
    pub solid_mass: Real,
    /// Principal moments of the hollow body (kg·m²), in the hull's principal frame.
    pub inertia: PrincipalInertia,
    /// Unit axis from base to tip, in the body (principal) frame.
    pub axis_body: Vector,
    /// Cavity: circumradius (m) and extent along the axis in the input frame (m).
    pub cavity_radius: Real,
    pub cavity_x: (Real, Real),
}

impl Projectile {
    /// Builds the hull and the hollow body's mass properties (see the module docs).
    pub fn new(params: ProjectileParams) -> Result<Self, ProjectileError> {
        params.validate()?;
        let n = params.circumferential_divisions;
        let mut points = Vec::with_capacity(n * (params.head_divisions + 1) + 1);
        let ring = |x: Real, r: Real, out: &mut Vec<Point>| {
            for k in 0..n {
                let t = 2.0 * std::f64::consts::PI * k as Real / n as Real;
                out.push(Point::new(x, r * t.cos(), r * t.sin()));
            }
        };
        ring(0.0, 0.5 * params.diameter, &mut points);
        for (x, r) in params.head_profile() {
            if r > 0.0 {
                ring(x, r, &mut points);
            } else {
                points.push(Point::new(x, 0.0, 0.0));
            }
        }
        let (shape, input_from_body) = ConvexPolyhedron::from_points(&points)?;
        let solid = shape.mass_properties().clone();
        let centroid_x = input_from_body.translation.vector.x;
        let shoulder = params.length - params.nose_length();
        let half = (centroid_x - params.base_thickness).min(shoulder - centroid_x);
        if half <= 0.0 {
            return Err(ProjectileError::InvalidParameter {
                name: "base_thickness",
                value: params.base_thickness,
                reason: "leaves no room for a cavity centred on the centroid",
            });
        }
        let cavity_radius = 0.5 * params.diameter - params.wall_thickness;
        let cavity_x = (centroid_x - half, centroid_x + half);
        let (cv, cf) = prism(n, cavity_radius, cavity_x.0, cavity_x.1);
        let cv_body: Vec<Point> = cv
            .iter()
            .map(|p| input_from_body.inverse_transform_point(p))
            .collect();
        let cavity = polyhedron_mass_properties(&cv_body, &cf);
        let (mass, com, inertia) =
            hollow_mass_properties(&solid, &cavity, params.density, params.fill_density);
        let diag = inertia.diagonal();
        let off = (inertia - Matrix::from_diagonal(&diag)).abs().max();
        let ratio = off / diag.max();
        if ratio > 1e-9 || com.coords.norm() > 1e-9 * params.length {
            return Err(ProjectileError::NotPrincipal { ratio });
        }
        let axis_body = input_from_body.inverse_transform_vector(&Vector::x());
        Ok(Self {
            params,
            shape: Arc::new(shape),
            input_from_body,
            mass,
            solid_mass: params.density * solid.volume,
            inertia: PrincipalInertia::new(diag)?,
            axis_body,
            cavity_radius,
            cavity_x,
        })
    }

    /// The body pose that puts the tip at `tip` with the axis (base → tip) along the unit `direction`.
    pub fn pose_with_tip_at(&self, tip: &Point, direction: &Vector) -> Pose {
        let rotation = Rotation::rotation_between(&Vector::x(), direction)
            .unwrap_or_else(|| Rotation::from_axis_angle(&Vector::z_axis(), std::f64::consts::PI));
        let world_from_input = Pose::from_parts(
            (tip.coords - rotation * Vector::new(self.params.length, 0.0, 0.0)).into(),
            rotation,
        );
        world_from_input * self.input_from_body
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_ogive_profile_lies_on_the_arc_and_meets_the_cylinder() {
        let p = ProjectileParams::paper();
        let prof = p.head_profile();
        let shoulder = p.length - p.nose_length();
        let centre = (shoulder, -(p.ogive_radius - 0.5 * p.diameter));
        for &(x, r) in &prof {
            let dist = ((x - centre.0).powi(2) + (r - centre.1).powi(2)).sqrt();
            assert!(
                (dist - p.ogive_radius).abs() < 1e-12 * p.length,
                "ring ({x}, {r}) at {dist} from the arc centre, expected R = {}",
                p.ogive_radius
            );
        }
        assert_eq!(prof.len(), p.head_divisions + 1);
        assert!((prof[0].1 - 0.5 * p.diameter).abs() < 1e-15);
        assert!((prof[p.head_divisions].0 - p.length).abs() < 1e-15);
        // L_n = √(0.5² − 0.425²) = √0.069375 m.
        assert!((p.nose_length() - 0.069375f64.sqrt()).abs() < 1e-15);
    }
}
