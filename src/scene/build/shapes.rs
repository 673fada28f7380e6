//! `[[shape]]`: one builder per shape kind, and the few facts of a built [`Shape`] the other tables need
//! (mass properties, bounding radius).
//!
//! A new kind is one row of [`KINDS`] (its scene key, the `ShapeSection` field that describes it, its
//! builder), that field in [`kind_fields`], and its arms in [`volume_and_moments`] and
//! [`bounding_radius`].

use std::sync::Arc;

use crate::fixed_hash::FixedHashMap;
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::{ConvexPolyhedron, Shape, Sphere};

use super::super::schema::{SceneFile, ShapeSection};
use super::{Ctx, SceneError};

/// Builds the shape of one `[[shape]]` of a kind.
type Builder = fn(&Named) -> Result<(Shape, Pose), SceneError>;

/// The shape kinds of the scene format: the scene key, the one field that describes the kind, its
/// builder.
const KINDS: [(&str, &str, Builder); 4] = [
    ("box", "half_extents", box_shape),
    ("sphere", "radius", sphere_shape),
    ("polyhedron", "points", polyhedron_shape),
    ("ellipsoid", "semi_axes", ellipsoid_shape),
];

/// Which kind-specific fields a `[[shape]]` gives, in the order a misplaced one is reported.
fn kind_fields(s: &ShapeSection) -> [(&'static str, bool); 4] {
    [
        ("half_extents", s.half_extents.is_some()),
        ("radius", s.radius.is_some()),
        ("points", s.points.is_some()),
        ("semi_axes", s.semi_axes.is_some()),
    ]
}

/// The built shapes, each with the pose of its principal frame in the shape's own frame; the scene's
/// `[[shape]]` entries first (found by name), then the spheres of the body files.
pub(super) struct Shapes<'a> {
    pub list: Vec<(Shape, Pose)>,
    ids: FixedHashMap<&'a str, usize>,
}

impl<'a> Shapes<'a> {
    pub fn read(ctx: &Ctx, file: &'a SceneFile) -> Result<Self, SceneError> {
        let mut shapes = Shapes {
            list: Vec::new(),
            ids: FixedHashMap::default(),
        };
        for (k, s) in file.shapes.iter().enumerate() {
            let name = s.name.get_ref().as_str();
            if shapes.ids.contains_key(name) {
                return Err(ctx.invalid(
                    s.name.span(),
                    format!("shape[{k}].name"),
                    format!("duplicate shape '{name}'"),
                ));
            }
            let built = build_shape(ctx, file, k, s)?;
            shapes.ids.insert(name, shapes.list.len());
            shapes.list.push(built);
        }
        Ok(shapes)
    }

    /// The index of a `[[shape]]` by name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.ids.get(name).copied()
    }
}

/// One `[[shape]]`: its kind, no field of another kind, and the shape built from its own field.
fn build_shape(
    ctx: &Ctx,
    file: &SceneFile,
    k: usize,
    s: &ShapeSection,
) -> Result<(Shape, Pose), SceneError> {
    let kind = s.kind.get_ref().as_str();
    let Some((_, own, builder)) = KINDS.iter().find(|(key, _, _)| *key == kind) else {
        return Err(ctx.invalid(
            s.kind.span(),
            format!("shape[{k}].kind"),
            format!(
                "unknown shape kind '{kind}' (expected {})",
                expected_kinds()
            ),
        ));
    };
    for (field, is_present) in kind_fields(s) {
        if is_present && field != *own {
            return Err(ctx.invalid(
                s.kind.span(),
                format!("shape[{k}].{field}"),
                format!("a {kind} shape has no field {field}"),
            ));
        }
    }
    let named = Named { ctx, file, k, s };
    builder(&named)
}

/// `"box", "sphere", "polyhedron" or "ellipsoid"`.
fn expected_kinds() -> String {
    let quoted: Vec<String> = KINDS
        .iter()
        .map(|(key, _, _)| format!("\"{key}\""))
        .collect();
    let (last, rest) = quoted.split_last().expect("at least one kind");
    format!("{} or {last}", rest.join(", "))
}

/// A `[[shape]]` being built, with what its error messages name.
struct Named<'a> {
    ctx: &'a Ctx<'a>,
    /// The scene, whose bodies a hull error names.
    file: &'a SceneFile,
    k: usize,
    s: &'a ShapeSection,
}

impl Named<'_> {
    /// Which bodies use the shape; read only for an error message, so that building the shapes does not
    /// scan every body once per shape.
    fn used_by(&self) -> String {
        let users: Vec<&str> = self
            .file
            .bodies
            .iter()
            .filter(|b| b.shape.get_ref() == self.s.name.get_ref())
            .map(|b| b.name.get_ref().as_str())
            .collect();
        if users.is_empty() {
            String::from("not used by any body")
        } else {
            format!("used by body '{}'", users.join("', '"))
        }
    }

    fn field(&self, name: &str) -> String {
        format!("shape[{}].{name}", self.k)
    }

    /// The field a kind needs is absent.
    fn missing(&self, field: &str, message: &str) -> SceneError {
        self.ctx
            .invalid(self.s.kind.span(), self.field(field), message)
    }

    /// The convex hull of `points` (error on the line of `field`).
    fn hull(
        &self,
        points: &[Point],
        span: std::ops::Range<usize>,
        field: &str,
    ) -> Result<(Shape, Pose), SceneError> {
        let (p, frame) = ConvexPolyhedron::from_points(points).map_err(|e| {
            self.ctx.invalid(
                span,
                self.field(field),
                format!(
                    "shape '{}' ({}): {e}",
                    self.s.name.get_ref(),
                    self.used_by()
                ),
            )
        })?;
        Ok((Shape::Polyhedron(Arc::new(p)), frame))
    }
}

/// `kind = "box"`: a polyhedron from the eight corners ±half_extents.
fn box_shape(n: &Named) -> Result<(Shape, Pose), SceneError> {
    let h =
        n.s.half_extents
            .as_ref()
            .ok_or_else(|| n.missing("half_extents", "a box needs half_extents"))?;
    let he = n.ctx.vector(h, &n.field("half_extents"))?;
    if he.iter().any(|x| *x <= 0.0) {
        return Err(n.ctx.invalid(
            h.span(),
            n.field("half_extents"),
            format!("must be positive, got {:?}", h.get_ref()),
        ));
    }
    let corners: Vec<Point> = (0..8)
        .map(|i| {
            let sgn = |bit: usize| if i & (1 << bit) != 0 { 1.0 } else { -1.0 };
            Point::new(sgn(0) * he.x, sgn(1) * he.y, sgn(2) * he.z)
        })
        .collect();
    n.hull(&corners, h.span(), "half_extents")
}

/// `kind = "sphere"`.
fn sphere_shape(n: &Named) -> Result<(Shape, Pose), SceneError> {
    let r =
        n.s.radius
            .as_ref()
            .ok_or_else(|| n.missing("radius", "a sphere needs a radius"))?;
    let radius = n.ctx.positive(r, &n.field("radius"))?;
    let sphere = Sphere::new(radius)
        .map_err(|e| n.ctx.invalid(r.span(), n.field("radius"), e.to_string()))?;
    Ok((Shape::Sphere(sphere), Pose::identity()))
}

/// `kind = "ellipsoid"`: semi-axes (a, b, c) along the shape's x, y, z.
fn ellipsoid_shape(n: &Named) -> Result<(Shape, Pose), SceneError> {
    let axes =
        n.s.semi_axes
            .as_ref()
            .ok_or_else(|| n.missing("semi_axes", "an ellipsoid needs semi_axes"))?;
    let v = n.ctx.vector(axes, &n.field("semi_axes"))?;
    let shape = Shape::ellipsoid(v.x, v.y, v.z).map_err(|e| {
        n.ctx.invalid(
            axes.span(),
            n.field("semi_axes"),
            format!("must be positive, got {:?}: {e}", axes.get_ref()),
        )
    })?;
    Ok((shape, Pose::identity()))
}

/// `kind = "polyhedron"`: the convex hull of the points.
fn polyhedron_shape(n: &Named) -> Result<(Shape, Pose), SceneError> {
    let pts =
        n.s.points
            .as_ref()
            .ok_or_else(|| n.missing("points", "a polyhedron needs points"))?;
    let points: Vec<Point> = pts
        .get_ref()
        .iter()
        .map(|p| Point::new(p[0], p[1], p[2]))
        .collect();
    n.hull(&points, pts.span(), "points")
}

/// The volume (m³) and principal moments per unit density (m⁵) of a body's shape.
pub(super) fn volume_and_moments(shape: &Shape) -> (Real, Vector) {
    match shape {
        Shape::Polyhedron(p) => (
            p.mass_properties().volume,
            p.mass_properties().principal_moments,
        ),
        Shape::Sphere(s) => (
            s.mass_properties().volume,
            s.mass_properties().principal_moments,
        ),
        Shape::Plane(_) => unreachable!("scene shapes are never planes"),
        other => {
            let convex = other.convex().expect("every shape but a plane is convex");
            let m = convex.mass_properties();
            (m.volume, m.principal_moments)
        }
    }
}

/// The bounding radius about the centre of mass (m): the lever arm of the time step's rotational factor.
pub(super) fn bounding_radius(shape: &Shape) -> Real {
    match shape {
        Shape::Polyhedron(p) => p.bounding_radius(),
        Shape::Sphere(s) => s.radius(),
        Shape::Plane(_) => 0.0,
        other => other.convex().map_or(0.0, |c| c.bounding_radius()),
    }
}
