//! Validation of a parsed scene and construction of the [`Simulation`] it describes.
//!
//! Every check names the file, the line (from the span toml keeps for each value) and the field, in the
//! form `FILE:LINE: FIELD: what is wrong`, e.g. `scenes/drop.toml:14: interaction[0].normal_stiffness:
//! must be finite and positive, got -1`.

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use toml::Spanned;

use crate::dynamics::{Motion, PrincipalInertia, RigidBody, ViscousDamping};
use crate::law::{ContactModel, DampingLaw, LawError, NormalLaw, TangentialLaw};
use crate::math::{Point, Pose, Real, Rotation, Vector};
use crate::shape::{ConvexPolyhedron, Plane, Shape, Sphere};
use crate::world::{MaterialTable, StepParams, Wall, World};

use super::schema::{SceneFile, Vec3};
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
    let mut material_ids: HashMap<&str, u32> = HashMap::new();
    let mut densities = Vec::new();
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
        let k_n = ctx.positive(&it.normal_stiffness, &f("normal_stiffness"))?;
        let exponent = match (it.law.get_ref().as_str(), &it.exponent) {
            ("linear", None) => 1.0,
            ("linear", Some(e)) => {
                return Err(ctx.invalid(
                    e.span(),
                    f("exponent"),
                    "the linear law has no exponent (use law = \"power\")",
                ))
            }
            ("power", Some(e)) => *e.get_ref(),
            ("power", None) => {
                return Err(ctx.invalid(
                    it.law.span(),
                    f("exponent"),
                    "the power law needs an exponent n (1 ≤ n ≤ 3)",
                ))
            }
            (other, _) => {
                return Err(ctx.invalid(
                    it.law.span(),
                    f("law"),
                    format!("unknown law '{other}' (expected \"linear\" or \"power\")"),
                ))
            }
        };
        let exponent_span = it.exponent.as_ref().map_or(it.law.span(), |e| e.span());
        let normal =
            NormalLaw::new(k_n, exponent).map_err(|e| ctx.law(exponent_span, &f("exponent"), e))?;
        let damping = DampingLaw::from_restitution(exponent, *it.restitution.get_ref())
            .map_err(|e| ctx.law(it.restitution.span(), &f("restitution"), e))?;
        let mu = *it.friction.get_ref();
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(ctx.invalid(
                it.friction.span(),
                f("friction"),
                format!("must be finite and ≥ 0, got {mu}"),
            ));
        }
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
        materials.set_model(
            ia,
            ib,
            ContactModel {
                normal,
                damping,
                tangential,
            },
        );
    }

    // Shapes.
    let mut shape_ids: HashMap<&str, usize> = HashMap::new();
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
    let mut names: HashMap<&str, ()> = HashMap::new();
    for (k, b) in file.bodies.iter().enumerate() {
        let f = |x: &str| format!("body[{k}].{x}");
        let name = b.name.get_ref().as_str();
        if name.is_empty() || name.contains([',', '"', '\n', '\r']) {
            return Err(ctx.invalid(b.name.span(), f("name"), format!("'{name}' must be non-empty without commas, quotes or line breaks (it is the id column of bodies.csv)")));
        }
        if names.insert(name, ()).is_some() {
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
        }
        world_bodies.push((
            name,
            shape_index,
            mat,
            body,
            *frame,
            b.track.unwrap_or(false),
        ));
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

    // The time step.
    let speed = sim
        .characteristic_speed
        .as_ref()
        .map(|v| ctx.positive(v, "simulation.characteristic_speed"))
        .transpose()?;
    let n_mat = materials.len();
    let mut lightest = vec![Real::INFINITY; n_mat];
    let mut has_obstacle = vec![false; n_mat];
    let mut kappa: Real = 1.0;
    for (_, shape_index, mat, body, _, _) in &world_bodies {
        if body.is_dynamic() {
            lightest[*mat as usize] = lightest[*mat as usize].min(body.mass);
            let r = match &shapes[*shape_index].0 {
                Shape::Polyhedron(p) => p.bounding_radius(),
                Shape::Sphere(s) => s.radius(),
                Shape::Plane(_) => 0.0,
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
            let mut candidates = Vec::new();
            if ma.is_finite() && mb.is_finite() {
                candidates.push(ma * mb / (ma + mb));
            }
            if ma.is_finite() && has_obstacle[b] {
                candidates.push(ma);
            }
            if mb.is_finite() && has_obstacle[a] {
                candidates.push(mb);
            }
            if let Some(m) = candidates.into_iter().reduce(Real::min) {
                estimates.push(PairEstimate {
                    model: *model,
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
            .add_body(name, shape_index_in_world[shape_index], mat, body)
            .map_err(|e| {
                ctx.invalid(
                    file.bodies[k].material.span(),
                    format!("body[{k}].material"),
                    e.to_string(),
                )
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
