//! Validation of a parsed scene and construction of the [`Simulation`] it describes.
//!
//! Every check names the file, the line (from the span toml keeps for each value) and the field, in the
//! form `FILE:LINE: FIELD: what is wrong`, e.g. `scenes/drop.toml:14: interaction[0].normal_stiffness:
//! must be finite and positive, got -1`.

use crate::fixed_hash::FixedHashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use toml::Spanned;

use crate::contact::pair_smoothing::PairSmoothing;
use crate::contact::wall_depth::WallDepth;
use crate::dynamics::{Motion, PrincipalInertia, RigidBody, ViscousDamping};
use crate::law::hertz_mindlin::{material_hertz_mindlin, ElasticMaterial, HertzMindlinOptions};
use crate::law::pair::contact_radius;
use crate::law::{
    ContactModel, DampingLaw, LawError, NormalLaw, RadiusScaling, SpringRotation, TangentialLaw,
};
use crate::math::{Point, Pose, Real, Rotation, Vector};
use crate::shape::{ConvexPolyhedron, Plane, Shape, Sphere};
use crate::world::{MaterialTable, StepParams, Wall, World};

use super::body_file::read_sphere_table;
use super::schema::{SceneFile, SimulationSection, Vec3};
use super::time_step::{contact_time_and_limit, PairEstimate, TimeStepInfo, TimeStepIssue};

/// Why a scene could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{}: cannot read the scene file: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown field, a missing field or a value of the wrong type.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// A value that parses but is not valid.
    #[error("{}:{line}: {field}: {message}", path.display())]
    Invalid {
        path: PathBuf,
        line: usize,
        field: String,
        message: String,
    },
}

/// A scene ready to run.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Simulation {
    pub world: World,
    pub params: StepParams,
    pub time_step: TimeStepInfo,
    /// Simulated duration (s) and the number of steps that covers it.
    pub end_time: Real,
    pub steps: u64,
    /// Output every this many steps.
    pub output_every: u64,
    /// Bodies written to `bodies.csv`, in file order.
    pub tracked: Vec<usize>,
    /// For each body, the pose of its principal frame in the shape's own (input) frame: the body's
    /// orientation as the user gave it is `orientation · frame.rotation⁻¹`.
    pub frames: Vec<Pose>,
}

impl Simulation {
    /// The orientation of body `i`'s own (input) frame, as the scene gave it.
    pub fn input_orientation(&self, i: usize) -> Rotation {
        self.world.bodies[i].orientation * self.frames[i].rotation.inverse()
    }
}

/// Reads and builds the scene at `path`.
pub fn load_scene(path: &Path) -> Result<Simulation, SceneError> {
    let source = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    parse_scene(&source, path)
}

/// Builds a scene from its text; `path` is used in the messages.
pub fn parse_scene(source: &str, path: &Path) -> Result<Simulation, SceneError> {
    let ctx = Ctx { path, source };
    let file: SceneFile = toml::from_str(source).map_err(|e| {
        let (line, column) = e.span().map(|s| ctx.line_column(s.start)).unwrap_or((0, 0));
        SceneError::Parse {
            path: path.to_owned(),
            line,
            column,
            message: e.message().trim().to_owned(),
        }
    })?;
    build(&ctx, &file)
}

struct Ctx<'a> {
    path: &'a Path,
    source: &'a str,
}

impl Ctx<'_> {
    fn line_column(&self, offset: usize) -> (usize, usize) {
        let before = &self.source[..offset.min(self.source.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        (line, column)
    }

    fn invalid(
        &self,
        span: Range<usize>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_owned(),
            line: self.line_column(span.start).0,
            field: field.into(),
            message: message.into(),
        }
    }

    fn positive(&self, v: &Spanned<f64>, field: &str) -> Result<Real, SceneError> {
        let x = *v.get_ref();
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(
                v.span(),
                field,
                format!("must be finite and positive, got {x}"),
            ))
        }
    }

    fn vector(&self, v: &Spanned<Vec3>, field: &str) -> Result<Vector, SceneError> {
        let a = v.get_ref();
        if a.iter().all(|x| x.is_finite()) {
            Ok(Vector::new(a[0], a[1], a[2]))
        } else {
            Err(self.invalid(v.span(), field, format!("must be finite, got {a:?}")))
        }
    }

    fn law(&self, span: Range<usize>, field: &str, e: LawError) -> SceneError {
        self.invalid(span, field, e.to_string())
    }
}

fn build(ctx: &Ctx, file: &SceneFile) -> Result<Simulation, SceneError> {
    let sim = &file.simulation;
    let gravity = ctx.vector(&sim.gravity, "simulation.gravity")?;
    let end_time = ctx.positive(&sim.end_time, "simulation.end_time")?;
    let output_interval = ctx.positive(&sim.output_interval, "simulation.output_interval")?;

    // Materials.
    let mut materials = MaterialTable::default();
    let mut material_ids: FixedHashMap<&str, u32> = FixedHashMap::default();
    let mut densities = Vec::new();
    let mut elastic: Vec<Option<ElasticMaterial>> = Vec::new();
    for (k, m) in file.materials.iter().enumerate() {
        let name = m.name.get_ref().as_str();
        if material_ids.contains_key(name) {
            return Err(ctx.invalid(
                m.name.span(),
                format!("material[{k}].name"),
                format!("duplicate material '{name}'"),
            ));
        }
        densities.push(ctx.positive(&m.density, &format!("material[{k}].density"))?);
        elastic.push(match (&m.young_modulus, &m.poisson_ratio) {
            (None, None) => None,
            (Some(young), Some(poisson)) => {
                let e = ctx.positive(young, &format!("material[{k}].young_modulus"))?;
                Some(ElasticMaterial::new(e, *poisson.get_ref()).map_err(|err| {
                    ctx.law(poisson.span(), &format!("material[{k}].poisson_ratio"), err)
                })?)
            }
            (Some(young), None) => {
                return Err(ctx.invalid(
                    young.span(),
                    format!("material[{k}].poisson_ratio"),
                    "young_modulus needs poisson_ratio as well",
                ))
            }
            (None, Some(poisson)) => {
                return Err(ctx.invalid(
                    poisson.span(),
                    format!("material[{k}].young_modulus"),
                    "poisson_ratio needs young_modulus as well",
                ))
            }
        });
        material_ids.insert(name, materials.add_material(name));
    }
    let material = |name: &Spanned<String>, field: String| {
        material_ids
            .get(name.get_ref().as_str())
            .copied()
            .ok_or_else(|| {
                ctx.invalid(
                    name.span(),
                    field,
                    format!("unknown material '{}'", name.get_ref()),
                )
            })
    };

    // Interactions.
    for (k, it) in file.interactions.iter().enumerate() {
        let f = |s: &str| format!("interaction[{k}].{s}");
        let [a, b] = it.materials.get_ref();
        let ids = [a, b].map(|n| material_ids.get(n.as_str()).copied());
        let (Some(ia), Some(ib)) = (ids[0], ids[1]) else {
            let missing = if ids[0].is_none() { a } else { b };
            return Err(ctx.invalid(
                it.materials.span(),
                f("materials"),
                format!("unknown material '{missing}'"),
            ));
        };
        if materials.model(ia, ib).is_some() {
            return Err(ctx.invalid(
                it.materials.span(),
                f("materials"),
                format!("a law for ('{a}', '{b}') is already given"),
            ));
        }
        let mu = *it.friction.get_ref();
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(ctx.invalid(
                it.friction.span(),
                f("friction"),
                format!("must be finite and ≥ 0, got {mu}"),
            ));
        }
        let limit_force = it.limit_force.as_ref().is_some_and(|b| *b.get_ref());
        let law = it.law.get_ref().as_str();
        let model = match law {
            "hertz_mindlin" => {
                let foreign = [
                    (
                        "normal_stiffness",
                        it.normal_stiffness.as_ref().map(|v| v.span()),
                    ),
                    ("exponent", it.exponent.as_ref().map(|v| v.span())),
                    (
                        "tangential_stiffness",
                        it.tangential_stiffness.as_ref().map(|v| v.span()),
                    ),
                    (
                        "normal_damping",
                        it.normal_damping.as_ref().map(|v| v.span()),
                    ),
                ];
                for (field, span) in foreign {
                    if let Some(span) = span {
                        return Err(ctx.invalid(span, f(field), format!("the hertz_mindlin law takes no {field}: its stiffnesses follow from the materials' young_modulus and poisson_ratio and each contact's R*, its damping from the restitution")));
                    }
                }
                let restitution = it.restitution.as_ref().ok_or_else(|| {
                    ctx.invalid(
                        it.law.span(),
                        f("restitution"),
                        "the hertz_mindlin law needs a restitution e (0 < e ≤ 1)",
                    )
                })?;
                let constants = |id: u32| {
                    elastic[id as usize].ok_or_else(|| {
                        let m = &file.materials[id as usize];
                        ctx.invalid(
                            m.name.span(),
                            format!("material[{id}].young_modulus"),
                            format!("material '{}' needs young_modulus and poisson_ratio: interaction[{k}] uses the hertz_mindlin law", m.name.get_ref()),
                        )
                    })
                };
                let options = HertzMindlinOptions {
                    tangential_damping: it.tangential_damping.as_ref().is_none_or(|b| *b.get_ref()),
                    limit_force,
                };
                material_hertz_mindlin(
                    &constants(ia)?,
                    &constants(ib)?,
                    *restitution.get_ref(),
                    mu,
                    options,
                )
                .map_err(|e| ctx.law(restitution.span(), &f("restitution"), e))?
            }
            "linear" | "power" => {
                if let Some(td) = &it.tangential_damping {
                    return Err(ctx.invalid(
                        td.span(),
                        f("tangential_damping"),
                        format!("the {law} law has no tangential dashpot (only hertz_mindlin)"),
                    ));
                }
                let k_n_value = it.normal_stiffness.as_ref().ok_or_else(|| {
                    ctx.invalid(
                        it.law.span(),
                        f("normal_stiffness"),
                        format!("the {law} law needs normal_stiffness"),
                    )
                })?;
                let k_n = ctx.positive(k_n_value, &f("normal_stiffness"))?;
                let exponent = match (law, &it.exponent) {
                    ("linear", None) => 1.0,
                    ("linear", Some(e)) => {
                        return Err(ctx.invalid(
                            e.span(),
                            f("exponent"),
                            "the linear law has no exponent (use law = \"power\")",
                        ))
                    }
                    (_, Some(e)) => *e.get_ref(),
                    (_, None) => {
                        return Err(ctx.invalid(
                            it.law.span(),
                            f("exponent"),
                            "the power law needs an exponent n (1 ≤ n ≤ 3)",
                        ))
                    }
                };
                let exponent_span = it.exponent.as_ref().map_or(it.law.span(), |e| e.span());
                let mut normal = NormalLaw::new(k_n, exponent)
                    .map_err(|e| ctx.law(exponent_span, &f("exponent"), e))?;
                if limit_force {
                    normal = normal.with_force_limit();
                }
                let damping = match (&it.restitution, &it.normal_damping) {
                    (Some(e), None) => DampingLaw::from_restitution(exponent, *e.get_ref())
                        .map_err(|err| ctx.law(e.span(), &f("restitution"), err))?,
                    (None, Some(c)) if law == "linear" => DampingLaw::dashpot(*c.get_ref())
                        .map_err(|err| ctx.law(c.span(), &f("normal_damping"), err))?,
                    (None, Some(c)) => {
                        return Err(ctx.invalid(c.span(), f("normal_damping"), "a constant dashpot is available for the linear law only; give a restitution"))
                    }
                    (Some(_), Some(c)) => {
                        return Err(ctx.invalid(c.span(), f("normal_damping"), "give either restitution or normal_damping, not both"))
                    }
                    (None, None) => {
                        return Err(ctx.invalid(it.law.span(), f("restitution"), "give a restitution e (0 < e ≤ 1) or, for the linear law, a normal_damping c_n (N s/m)"))
                    }
                };
                // No tangential history at all when μ = 0: the spring could carry no force.
                let tangential = match (&it.tangential_stiffness, mu > 0.0) {
                    (None, false) => TangentialLaw::None,
                    (Some(k_t), _) => {
                        let k_t_value = ctx.positive(k_t, &f("tangential_stiffness"))?;
                        if mu > 0.0 {
                            TangentialLaw::spring(k_t_value, mu)
                                .map_err(|e| ctx.law(k_t.span(), &f("tangential_stiffness"), e))?
                        } else {
                            TangentialLaw::None
                        }
                    }
                    (None, true) => {
                        return Err(ctx.invalid(
                            it.friction.span(),
                            f("tangential_stiffness"),
                            "friction > 0 needs a tangential_stiffness",
                        ))
                    }
                };
                ContactModel {
                    normal,
                    damping,
                    tangential,
                }
            }
            other => {
                return Err(ctx.invalid(
                    it.law.span(),
                    f("law"),
                    format!(
                    "unknown law '{other}' (expected \"linear\", \"power\" or \"hertz_mindlin\")"
                ),
                ))
            }
        };
        let model = match &it.spring_rotation {
            None => model,
            Some(r) => {
                let rotation = match r.get_ref().as_str() {
                    "exact" => SpringRotation::Exact,
                    "projection" => SpringRotation::Projection,
                    other => {
                        return Err(ctx.invalid(
                            r.span(),
                            f("spring_rotation"),
                            format!("unknown spring_rotation '{other}' (expected \"exact\" or \"projection\")"),
                        ))
                    }
                };
                ContactModel {
                    tangential: model.tangential.with_rotation(rotation),
                    ..model
                }
            }
        };
        materials.set_model(ia, ib, model);
    }

    // Shapes.
    let mut shape_ids: FixedHashMap<&str, usize> = FixedHashMap::default();
    let mut shapes: Vec<(Shape, Pose)> = Vec::new();
    for (k, s) in file.shapes.iter().enumerate() {
        let f = |x: &str| format!("shape[{k}].{x}");
        let name = s.name.get_ref().as_str();
        if shape_ids.contains_key(name) {
            return Err(ctx.invalid(
                s.name.span(),
                f("name"),
                format!("duplicate shape '{name}'"),
            ));
        }
        let users: Vec<&str> = file
            .bodies
            .iter()
            .filter(|b| b.shape.get_ref() == name)
            .map(|b| b.name.get_ref().as_str())
            .collect();
        let used_by = if users.is_empty() {
            String::from("not used by any body")
        } else {
            format!("used by body '{}'", users.join("', '"))
        };
        let kind = s.kind.get_ref().as_str();
        let expect_only = |present: [(&str, bool); 3]| -> Result<(), SceneError> {
            for (field, is_present) in present {
                if is_present {
                    return Err(ctx.invalid(
                        s.kind.span(),
                        f(field),
                        format!("a {kind} shape has no field {field}"),
                    ));
                }
            }
            Ok(())
        };
        let built = match kind {
            "box" => {
                expect_only([
                    ("radius", s.radius.is_some()),
                    ("points", s.points.is_some()),
                    ("", false),
                ])?;
                let h = s.half_extents.as_ref().ok_or_else(|| {
                    ctx.invalid(s.kind.span(), f("half_extents"), "a box needs half_extents")
                })?;
                let he = ctx.vector(h, &f("half_extents"))?;
                if he.iter().any(|x| *x <= 0.0) {
                    return Err(ctx.invalid(
                        h.span(),
                        f("half_extents"),
                        format!("must be positive, got {:?}", h.get_ref()),
                    ));
                }
                let corners: Vec<Point> = (0..8)
                    .map(|i| {
                        let sgn = |bit: usize| if i & (1 << bit) != 0 { 1.0 } else { -1.0 };
                        Point::new(sgn(0) * he.x, sgn(1) * he.y, sgn(2) * he.z)
                    })
                    .collect();
                let (p, frame) = ConvexPolyhedron::from_points(&corners).map_err(|e| {
                    ctx.invalid(
                        h.span(),
                        f("half_extents"),
                        format!("shape '{name}' ({used_by}): {e}"),
                    )
                })?;
                (Shape::Polyhedron(Arc::new(p)), frame)
            }
            "sphere" => {
                expect_only([
                    ("half_extents", s.half_extents.is_some()),
                    ("points", s.points.is_some()),
                    ("", false),
                ])?;
                let r = s.radius.as_ref().ok_or_else(|| {
                    ctx.invalid(s.kind.span(), f("radius"), "a sphere needs a radius")
                })?;
                let radius = ctx.positive(r, &f("radius"))?;
                let sphere = Sphere::new(radius)
                    .map_err(|e| ctx.invalid(r.span(), f("radius"), e.to_string()))?;
                (Shape::Sphere(sphere), Pose::identity())
            }
            "polyhedron" => {
                expect_only([
                    ("half_extents", s.half_extents.is_some()),
                    ("radius", s.radius.is_some()),
                    ("", false),
                ])?;
                let pts = s.points.as_ref().ok_or_else(|| {
                    ctx.invalid(s.kind.span(), f("points"), "a polyhedron needs points")
                })?;
                let points: Vec<Point> = pts
                    .get_ref()
                    .iter()
                    .map(|p| Point::new(p[0], p[1], p[2]))
                    .collect();
                let (p, frame) = ConvexPolyhedron::from_points(&points).map_err(|e| {
                    ctx.invalid(
                        pts.span(),
                        f("points"),
                        format!("shape '{name}' ({used_by}): {e}"),
                    )
                })?;
                (Shape::Polyhedron(Arc::new(p)), frame)
            }
            other => {
                return Err(ctx.invalid(
                    s.kind.span(),
                    f("kind"),
                    format!(
                    "unknown shape kind '{other}' (expected \"box\", \"sphere\" or \"polyhedron\")"
                ),
                ))
            }
        };
        shape_ids.insert(name, shapes.len());
        shapes.push(built);
    }

    // Bodies.
    let mut world_bodies = Vec::new();
    // Where each body was given: the span and field an error about it names.
    let mut origins: Vec<(Range<usize>, String)> = Vec::new();
    let mut names: FixedHashMap<String, ()> = FixedHashMap::default();
    for (k, b) in file.bodies.iter().enumerate() {
        let f = |x: &str| format!("body[{k}].{x}");
        let name = b.name.get_ref().as_str();
        if name.is_empty() || name.contains([',', '"', '\n', '\r']) {
            return Err(ctx.invalid(b.name.span(), f("name"), format!("'{name}' must be non-empty without commas, quotes or line breaks (it is the id column of bodies.csv)")));
        }
        if names.insert(name.to_owned(), ()).is_some() {
            return Err(ctx.invalid(b.name.span(), f("name"), format!("duplicate body '{name}'")));
        }
        let shape_index = *shape_ids.get(b.shape.get_ref().as_str()).ok_or_else(|| {
            ctx.invalid(
                b.shape.span(),
                f("shape"),
                format!("unknown shape '{}'", b.shape.get_ref()),
            )
        })?;
        let mat = material(&b.material, f("material"))?;
        let position = ctx.vector(&b.position, &f("position"))?;
        let orientation = match (&b.orientation, &b.axis_angle) {
            (Some(_), Some(aa)) => {
                return Err(ctx.invalid(
                    aa.span(),
                    f("axis_angle"),
                    "give either orientation or axis_angle, not both",
                ))
            }
            (Some(q), None) => {
                let [w, x, y, z] = *q.get_ref();
                let norm = (w * w + x * x + y * y + z * z).sqrt();
                if !norm.is_finite() || (norm - 1.0).abs() > 1e-6 {
                    return Err(ctx.invalid(
                        q.span(),
                        f("orientation"),
                        format!("must be a unit quaternion [w, x, y, z], got norm {norm}"),
                    ));
                }
                Rotation::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
            }
            (None, Some(aa)) => Rotation::from_scaled_axis(ctx.vector(aa, &f("axis_angle"))?),
            (None, None) => Rotation::identity(),
        };
        let velocity = b
            .velocity
            .as_ref()
            .map(|v| ctx.vector(v, &f("velocity")))
            .transpose()?
            .unwrap_or_else(Vector::zeros);
        let omega = b
            .angular_velocity
            .as_ref()
            .map(|v| ctx.vector(v, &f("angular_velocity")))
            .transpose()?
            .unwrap_or_else(Vector::zeros);
        let motion = match b.motion.as_ref().map(|m| (m.get_ref().as_str(), m.span())) {
            None | Some(("dynamic", _)) => Motion::Dynamic,
            Some(("fixed", _)) => Motion::Fixed,
            Some(("prescribed", _)) => Motion::Prescribed {
                velocity,
                angular_velocity_world: omega,
            },
            Some((other, span)) => {
                return Err(ctx.invalid(
                    span,
                    f("motion"),
                    format!(
                    "unknown motion '{other}' (expected \"dynamic\", \"fixed\" or \"prescribed\")"
                ),
                ))
            }
        };
        let (shape, frame) = &shapes[shape_index];
        let density = densities[mat as usize];
        let (volume, moments) = match shape {
            Shape::Polyhedron(p) => (
                p.mass_properties().volume,
                p.mass_properties().principal_moments,
            ),
            Shape::Sphere(s) => (
                s.mass_properties().volume,
                s.mass_properties().principal_moments,
            ),
            Shape::Plane(_) => unreachable!("scene shapes are never planes"),
            other => match other.convex() {
                Some(c) => (
                    c.mass_properties().volume,
                    c.mass_properties().principal_moments,
                ),
                None => unreachable!("scene shapes are never planes"),
            },
        };
        let inertia = PrincipalInertia::new(moments * density)
            .map_err(|e| ctx.invalid(b.shape.span(), f("shape"), e.to_string()))?;
        let mut body = RigidBody::new_dynamic(Point::origin(), volume * density, inertia)
            .map_err(|e| ctx.invalid(b.material.span(), f("material"), e.to_string()))?;
        body.position = Point::from(position) + orientation * frame.translation.vector;
        body.orientation = orientation * frame.rotation;
        body.velocity = if matches!(motion, Motion::Fixed) {
            Vector::zeros()
        } else {
            velocity
        };
        body.motion = motion;
        if !matches!(motion, Motion::Fixed) {
            body.set_angular_velocity(&omega);
            // J ω can overflow for a finite but huge ω (or huge moments of inertia).
            if !body.angular_momentum.iter().all(|x| x.is_finite()) {
                let span = b
                    .angular_velocity
                    .as_ref()
                    .map(|v| v.span())
                    .unwrap_or_else(|| b.shape.span());
                return Err(ctx.invalid(
                    span,
                    f("angular_velocity"),
                    format!(
                        "the angular momentum J ω = {:?} is not finite (ω = {:?} rad/s, principal moments {:?} kg·m²)",
                        body.angular_momentum, omega, body.inertia.0
                    ),
                ));
            }
        }
        world_bodies.push((
            name.to_owned(),
            shape_index,
            mat,
            body,
            *frame,
            b.track.unwrap_or(false),
        ));
        origins.push((b.material.span(), f("material")));
    }

    // Bodies from CSV files.
    for (k, bf) in file.body_files.iter().enumerate() {
        let f = |x: &str| format!("body_file[{k}].{x}");
        let mat = material(&bf.material, f("material"))?;
        let relative = Path::new(bf.path.get_ref());
        let csv_path = match ctx.path.parent() {
            Some(dir) if relative.is_relative() => dir.join(relative),
            _ => relative.to_owned(),
        };
        let rows = read_sphere_table(&csv_path)
            .map_err(|e| ctx.invalid(bf.path.span(), f("path"), e.to_string()))?;
        let use_file_velocities = match bf
            .velocities
            .as_ref()
            .map(|v| (v.get_ref().as_str(), v.span()))
        {
            None | Some(("file", _)) => true,
            Some(("zero", _)) => false,
            Some((other, span)) => {
                return Err(ctx.invalid(
                    span,
                    f("velocities"),
                    format!("unknown choice '{other}' (expected \"file\" or \"zero\")"),
                ))
            }
        };
        if let (Some(v), None) = (&bf.velocities, &rows[0].velocity) {
            if v.get_ref() == "file" {
                return Err(ctx.invalid(
                    v.span(),
                    f("velocities"),
                    format!("{} has no vx, vy, vz columns", csv_path.display()),
                ));
            }
        }
        let prefix = bf.name_prefix.get_ref();
        let density = densities[mat as usize];
        for row in rows {
            let name = format!("{prefix}{}", row.id);
            if names.insert(name.clone(), ()).is_some() {
                return Err(ctx.invalid(
                    bf.name_prefix.span(),
                    f("name_prefix"),
                    format!("duplicate body '{name}' (from {})", csv_path.display()),
                ));
            }
            let sphere = Sphere::new(row.radius).map_err(|e| {
                ctx.invalid(
                    bf.path.span(),
                    f("path"),
                    format!("{}: body '{name}': {e}", csv_path.display()),
                )
            })?;
            let props = sphere.mass_properties();
            let inertia = PrincipalInertia::new(props.principal_moments * density)
                .map_err(|e| ctx.invalid(bf.material.span(), f("material"), e.to_string()))?;
            let mut body =
                RigidBody::new_dynamic(Point::from(row.position), props.volume * density, inertia)
                    .map_err(|e| ctx.invalid(bf.material.span(), f("material"), e.to_string()))?;
            if use_file_velocities {
                body.velocity = row.velocity.unwrap_or_else(Vector::zeros);
            }
            shapes.push((Shape::Sphere(sphere), Pose::identity()));
            world_bodies.push((
                name,
                shapes.len() - 1,
                mat,
                body,
                Pose::identity(),
                bf.track.unwrap_or(false),
            ));
            origins.push((bf.material.span(), f("material")));
        }
    }

    // Walls.
    let mut walls = Vec::new();
    for (k, w) in file.walls.iter().enumerate() {
        let f = |x: &str| format!("wall[{k}].{x}");
        let mat = material(&w.material, f("material"))?;
        let point = ctx.vector(&w.point, &f("point"))?;
        let normal = ctx.vector(&w.normal, &f("normal"))?;
        let plane = Plane::new(normal, 0.0)
            .map_err(|e| ctx.invalid(w.normal.span(), f("normal"), e.to_string()))?;
        let velocity = w
            .velocity
            .as_ref()
            .map(|v| ctx.vector(v, &f("velocity")))
            .transpose()?
            .unwrap_or_else(Vector::zeros);
        walls.push((
            w.name.span(),
            Wall {
                name: w.name.get_ref().clone(),
                plane,
                pose: Pose::from_parts(point.into(), Rotation::identity()),
                velocity,
                material: mat,
            },
        ));
    }

    // Boxes: one inward-facing wall per closed face.
    for (k, bx) in file.boxes.iter().enumerate() {
        let f = |x: &str| format!("box[{k}].{x}");
        let mat = material(&bx.material, f("material"))?;
        let lo = ctx.vector(&bx.min, &f("min"))?;
        let hi = ctx.vector(&bx.max, &f("max"))?;
        if (0..3).any(|i| hi[i] <= lo[i]) {
            return Err(ctx.invalid(
                bx.max.span(),
                f("max"),
                format!(
                    "must exceed min in every coordinate, got min {:?}, max {:?}",
                    bx.min.get_ref(),
                    bx.max.get_ref()
                ),
            ));
        }
        const FACES: [&str; 6] = ["x-", "x+", "y-", "y+", "z-", "z+"];
        let check_face = |name: &str, span: Range<usize>, field: String| {
            if FACES.contains(&name) {
                Ok(())
            } else {
                Err(ctx.invalid(
                    span,
                    field,
                    format!("unknown face '{name}' (expected one of {FACES:?})"),
                ))
            }
        };
        let open: Vec<String> = match &bx.open {
            Some(o) => {
                for face in o.get_ref() {
                    check_face(face, o.span(), f("open"))?;
                }
                o.get_ref().clone()
            }
            None => Vec::new(),
        };
        let moving = match (&bx.moving_face, &bx.velocity) {
            (None, None) => None,
            (Some(face), Some(v)) => {
                check_face(face.get_ref(), face.span(), f("moving_face"))?;
                if open.contains(face.get_ref()) {
                    return Err(ctx.invalid(
                        face.span(),
                        f("moving_face"),
                        format!("face '{}' is open", face.get_ref()),
                    ));
                }
                Some((face.get_ref().clone(), ctx.vector(v, &f("velocity"))?))
            }
            (Some(face), None) => {
                return Err(ctx.invalid(
                    face.span(),
                    f("velocity"),
                    "a moving_face needs a velocity (m/s)",
                ))
            }
            (None, Some(v)) => {
                return Err(ctx.invalid(
                    v.span(),
                    f("moving_face"),
                    "a velocity needs the moving_face it belongs to",
                ))
            }
        };
        for (j, face) in FACES.iter().enumerate() {
            if open.iter().any(|o| o == face) {
                continue;
            }
            let axis = j / 2;
            let upper = j % 2 == 1;
            let mut normal = Vector::zeros();
            normal[axis] = if upper { -1.0 } else { 1.0 };
            let point = if upper { hi } else { lo };
            let plane = Plane::new(normal, 0.0)
                .map_err(|e| ctx.invalid(bx.min.span(), f("min"), e.to_string()))?;
            let velocity = match &moving {
                Some((m, v)) if m == face => *v,
                _ => Vector::zeros(),
            };
            walls.push((
                bx.name.span(),
                Wall {
                    name: format!("{}.{face}", bx.name.get_ref()),
                    plane,
                    pose: Pose::from_parts(point.into(), Rotation::identity()),
                    velocity,
                    material: mat,
                },
            ));
        }
    }

    // The time step.
    let speed = sim
        .characteristic_speed
        .as_ref()
        .map(|v| ctx.positive(v, "simulation.characteristic_speed"))
        .transpose()?;
    let n_mat = materials.len();
    let mut lightest = vec![Real::INFINITY; n_mat];
    // Contact radius of the lightest body of each material (for laws that scale with R*).
    let mut lightest_radius = vec![Real::INFINITY; n_mat];
    let mut has_obstacle = vec![false; n_mat];
    let mut kappa: Real = 1.0;
    for (_, shape_index, mat, body, _, _) in &world_bodies {
        if body.is_dynamic() {
            if body.mass < lightest[*mat as usize] {
                lightest[*mat as usize] = body.mass;
                lightest_radius[*mat as usize] =
                    contact_radius(&shapes[*shape_index].0).unwrap_or(Real::INFINITY);
            }
            let r = match &shapes[*shape_index].0 {
                Shape::Polyhedron(p) => p.bounding_radius(),
                Shape::Sphere(s) => s.radius(),
                Shape::Plane(_) => 0.0,
                other => other.convex().map_or(0.0, |c| c.bounding_radius()),
            };
            let j_min = body.inertia.0.min();
            kappa = kappa.max(1.0 + body.mass * r * r / j_min);
        } else {
            has_obstacle[*mat as usize] = true;
        }
    }
    for (_, w) in &walls {
        has_obstacle[w.material as usize] = true;
    }
    let mut estimates = Vec::new();
    for a in 0..n_mat {
        for b in a..n_mat {
            let Some(model) = materials.model(a as u32, b as u32) else {
                continue;
            };
            let (ma, mb) = (lightest[a], lightest[b]);
            let (ra, rb) = (lightest_radius[a], lightest_radius[b]);
            // (m*, R*) of each way the pair can meet; a wall or fixed body counts as flat (R* = R, the
            // stiffest Hertz contact of that body).
            let mut candidates = Vec::new();
            if ma.is_finite() && mb.is_finite() {
                candidates.push((ma * mb / (ma + mb), ra * rb / (ra + rb)));
            }
            if ma.is_finite() && has_obstacle[b] {
                candidates.push((ma, ra));
            }
            if mb.is_finite() && has_obstacle[a] {
                candidates.push((mb, rb));
            }
            for (m, r) in candidates {
                let model = match model.normal.radius_scaling {
                    RadiusScaling::Constant => *model,
                    RadiusScaling::SqrtEffectiveRadius => model.with_root_radius(r.sqrt()),
                };
                estimates.push(PairEstimate {
                    model,
                    effective_mass: m,
                });
            }
        }
    }
    let sim_span = sim.end_time.span();
    let (contact_time, limit) = match contact_time_and_limit(&estimates, kappa, speed) {
        Ok(x) => x,
        Err(TimeStepIssue::NeedsSpeed) => {
            return Err(ctx.invalid(sim_span, "simulation.characteristic_speed", "a power law with exponent ≠ 1 needs the characteristic impact speed (m/s) for its contact time and stability limit"))
        }
        // Nothing can touch: only a given step makes sense.
        Err(TimeStepIssue::NoContacts) => (Real::INFINITY, Real::INFINITY),
    };
    let (dt, derived) = match (&sim.time_step, &sim.steps_per_contact) {
        (Some(_), Some(n)) => {
            return Err(ctx.invalid(
                n.span(),
                "simulation.steps_per_contact",
                "give either time_step or steps_per_contact, not both",
            ))
        }
        (None, None) => {
            return Err(ctx.invalid(
                sim_span,
                "simulation.time_step",
                "give time_step (s) or steps_per_contact (N in Δt = t_c/N)",
            ))
        }
        (Some(dt), None) => {
            let value = ctx.positive(dt, "simulation.time_step")?;
            if value > limit {
                return Err(ctx.invalid(dt.span(), "simulation.time_step", format!(
                    "{value:e} s exceeds the stability limit {limit:e} s (2/ω_max of the stiffest contact; shortest contact time t_c = {contact_time:e} s)"
                )));
            }
            (value, false)
        }
        (None, Some(n)) => {
            let n_value = ctx.positive(n, "simulation.steps_per_contact")?;
            if !contact_time.is_finite() {
                return Err(ctx.invalid(n.span(), "simulation.steps_per_contact", "no two bodies of this scene can touch, so there is no contact time: give time_step"));
            }
            let value = contact_time / n_value;
            // A contact time that under- or overflowed (densities or stiffnesses near the ends of the f64
            // range) gives a step of 0 s or a non-finite one: refuse it here rather than at the first step.
            if !(value.is_finite() && value > 0.0) {
                return Err(ctx.invalid(n.span(), "simulation.steps_per_contact", format!(
                    "the derived step t_c/N = {value:e} s is not a positive finite time (shortest contact time t_c = {contact_time:e} s): check the densities and stiffnesses for values near the limits of f64"
                )));
            }
            if value > limit {
                return Err(ctx.invalid(n.span(), "simulation.steps_per_contact", format!(
                    "t_c/N = {value:e} s exceeds the stability limit {limit:e} s; N must be at least {:.1}", contact_time / limit
                )));
            }
            (value, true)
        }
    };
    let damping = match &sim.viscous_damping_rate {
        None => ViscousDamping::None,
        Some(rate) => {
            let r = *rate.get_ref();
            if !(r.is_finite() && r >= 0.0) {
                return Err(ctx.invalid(
                    rate.span(),
                    "simulation.viscous_damping_rate",
                    format!("must be finite and ≥ 0, got {r}"),
                ));
            }
            ViscousDamping::MassProportional(r)
        }
    };
    let min_radius = shapes
        .iter()
        .filter_map(|(s, _)| s.length_scale())
        .fold(Real::INFINITY, Real::min)
        * 0.5;
    let skin = match &sim.skin {
        Some(s) => ctx.positive(s, "simulation.skin")?,
        None if min_radius.is_finite() => 0.2 * min_radius,
        None => 0.0,
    };

    let mut world = World::new(gravity, materials, skin);
    let shape_index_in_world: Vec<u32> = shapes
        .iter()
        .map(|(s, _)| world.add_shape(s.clone()))
        .collect();
    let mut tracked = Vec::new();
    let mut frames = Vec::new();
    for (k, (name, shape_index, mat, body, frame, track)) in world_bodies.into_iter().enumerate() {
        let i = world
            .add_body(&name, shape_index_in_world[shape_index], mat, body)
            .map_err(|e| {
                let (span, field) = origins[k].clone();
                ctx.invalid(span, field, e.to_string())
            })?;
        frames.push(frame);
        if track {
            tracked.push(i as usize);
        }
    }
    for (k, (span, wall)) in walls.into_iter().enumerate() {
        world
            .add_wall(wall)
            .map_err(|e| ctx.invalid(span, format!("wall[{k}]"), e.to_string()))?;
    }
    let mut params = StepParams::new(dt);
    params.damping = damping;
    params.tolerances.wall_depth = wall_depth(ctx, sim)?;
    params.tolerances.pair_smoothing = pair_smoothing(ctx, sim)?;
    params.energy_ledger = sim.energy_ledger.as_ref().is_none_or(|l| *l.get_ref());
    let steps = super::run::steps_to(end_time, dt);
    let output_every = ((output_interval / dt).round() as u64).max(1);
    Ok(Simulation {
        world,
        params,
        time_step: TimeStepInfo {
            dt,
            derived,
            contact_time,
            stability_limit: limit,
        },
        end_time,
        steps,
        output_every,
        tracked,
        frames,
    })
}

/// `simulation.wall_depth` and `simulation.wall_depth_band`: how a polyhedron–wall contact turns the vertex
/// depths into the law's overlap. A band given with the deepest-vertex rule is refused (it would be ignored).
fn wall_depth(ctx: &Ctx, sim: &SimulationSection) -> Result<WallDepth, SceneError> {
    let band = match &sim.wall_depth_band {
        Some(b) => Some((ctx.positive(b, "simulation.wall_depth_band")?, b.span())),
        None => None,
    };
    let rule = sim
        .wall_depth
        .as_ref()
        .map(|r| (r.get_ref().as_str(), r.span()));
    match (rule, band) {
        (None | Some(("smoothed", _)), None) => Ok(WallDepth::default()),
        (None | Some(("smoothed", _)), Some((band, _))) => Ok(WallDepth::Smoothed { band }),
        (Some(("deepest_vertex", _)), None) => Ok(WallDepth::DeepestVertex),
        (Some(("deepest_vertex", _)), Some((_, span))) => Err(ctx.invalid(
            span,
            "simulation.wall_depth_band",
            "a band applies to wall_depth = \"smoothed\" only, not to \"deepest_vertex\"",
        )),
        (Some((other, span)), _) => Err(ctx.invalid(
            span,
            "simulation.wall_depth",
            format!("must be \"smoothed\" or \"deepest_vertex\", got \"{other}\""),
        )),
    }
}

/// `simulation.pair_smoothing` and `simulation.pair_smoothing_band`: the overlap a polyhedron–polyhedron
/// contact hands to the law. A band given with the exact overlap is refused (it would be ignored).
fn pair_smoothing(ctx: &Ctx, sim: &SimulationSection) -> Result<PairSmoothing, SceneError> {
    let band = match &sim.pair_smoothing_band {
        Some(b) => Some((ctx.positive(b, "simulation.pair_smoothing_band")?, b.span())),
        None => None,
    };
    let rule = sim
        .pair_smoothing
        .as_ref()
        .map(|r| (r.get_ref().as_str(), r.span()));
    match (rule, band) {
        (None | Some(("smoothed", _)), None) => Ok(PairSmoothing::default()),
        (None | Some(("smoothed", _)), Some((band, _))) => Ok(PairSmoothing::Smoothed { band }),
        (Some(("exact", _)), None) => Ok(PairSmoothing::Exact),
        (Some(("exact", _)), Some((_, span))) => Err(ctx.invalid(
            span,
            "simulation.pair_smoothing_band",
            "a band applies to pair_smoothing = \"smoothed\" only, not to \"exact\"",
        )),
        (Some((other, span)), _) => Err(ctx.invalid(
            span,
            "simulation.pair_smoothing",
            format!("must be \"smoothed\" or \"exact\", got \"{other}\""),
        )),
    }
}
