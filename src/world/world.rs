//! The world: plain data for every body, wall, shape and material pair, plus the state that persists between
//! steps (contact store, broad phase, the forces of the last evaluation, the energy ledger).
//!
//! # Layout
//! - Shapes live in a table ([`World::shapes`]); a body refers to its shape by index, so a thousand rocks
//!   cut from ten shapes share ten hulls.
//! - Bodies are stored as parallel arrays (struct of arrays): the integrator walks `bodies`, the broad
//!   phase walks `radii`, and the narrow phase reads `shape_of` without touching the rest.
//! - Walls are a separate list of planes, not bodies: a half-space has no bounding sphere for the broad
//!   phase and no mass. A wall is fixed or moves with a prescribed constant velocity (translation only); its
//!   pose is updated in the drift. Every body is tested against every wall whose plane its bounding sphere
//!   reaches, which is O(bodies × walls) cheap tests for the handful of walls of a box.
//! - The material-pair table maps an unordered pair of material ids to one [`ContactModel`]; a pair with
//!   no model is refused when a body or wall of those materials is added (so a step never meets one).

use crate::dynamics::RigidBody;
use crate::law::ContactModel;
use crate::math::{Pose, Real, Vector};
use crate::shape::Shape;

use super::broad_phase::BroadPhase;
use super::contact_store::ContactStore;
use super::energy::{EnergyLedger, EnergyReport};
use super::material_presence::MaterialPresence;
pub use super::material_presence::SetupStats;
use super::sleep_state::SleepState;

pub use super::loads::Loads;
pub use super::wall::Wall;

/// Why a body, wall or material could not be added.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    /// A body refers to a shape index that does not exist.
    #[error("body '{body}': shape index {shape} does not exist ({count} shapes)")]
    UnknownShape {
        /// Name of the body.
        body: String,
        /// The shape index given.
        shape: usize,
        /// Number of shapes in the world.
        count: usize,
    },
    /// A body was given a plane as its shape.
    #[error("body '{body}': a plane cannot be a body's shape (planes are walls)")]
    PlaneBody {
        /// Name of the body.
        body: String,
    },
    /// A body or wall refers to a material id that does not exist.
    #[error("'{owner}': material index {material} does not exist ({count} materials)")]
    UnknownMaterial {
        /// Name of the body or wall.
        owner: String,
        /// The material id given.
        material: usize,
        /// Number of materials in the table.
        count: usize,
    },
    /// Two materials that can meet have no contact law.
    #[error("'{owner}': no contact law for the material pair ('{a}', '{b}')")]
    MissingLaw {
        /// Name of the body or wall being added.
        owner: String,
        /// First material of the pair.
        a: String,
        /// Second material of the pair.
        b: String,
    },
    /// A body index that does not exist.
    #[error("body index {body} does not exist ({count} bodies)")]
    UnknownBody {
        /// The index given.
        body: usize,
        /// Number of bodies in the world.
        count: usize,
    },
    /// A wall index that does not exist.
    #[error("wall index {wall} does not exist ({count} walls)")]
    UnknownWall {
        /// The index given.
        wall: usize,
        /// Number of walls in the world.
        count: usize,
    },
    /// A body's position or velocity given to a setter is not finite.
    #[error("body '{body}': {what} must be finite")]
    NonFiniteBody {
        /// Name of the body.
        body: String,
        /// Which quantity.
        what: &'static str,
    },
    /// The gravity given is not finite.
    #[error("gravity must be finite")]
    NonFiniteGravity,
    /// A wall's position or velocity is not finite.
    #[error("wall '{wall}': {what} must be finite")]
    NonFiniteWall {
        /// Name of the wall.
        wall: String,
        /// Which quantity.
        what: &'static str,
    },
}

/// The symmetric table material pair → contact model.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MaterialTable {
    names: Vec<String>,
    /// Row-major n × n, symmetric.
    models: Vec<Option<ContactModel>>,
}

impl MaterialTable {
    /// Adds a material; returns its id.
    pub fn add_material(&mut self, name: &str) -> u32 {
        let n = self.names.len();
        let mut models = vec![None; (n + 1) * (n + 1)];
        for i in 0..n {
            for j in 0..n {
                models[i * (n + 1) + j] = self.models[i * n + j];
            }
        }
        self.models = models;
        self.names.push(name.to_owned());
        n as u32
    }

    /// Sets the model of the unordered pair (a, b).
    pub fn set_model(&mut self, a: u32, b: u32, model: ContactModel) {
        let n = self.names.len();
        let (a, b) = (a as usize, b as usize);
        self.models[a * n + b] = Some(model);
        self.models[b * n + a] = Some(model);
    }

    /// The model of the pair (a, b), if one was set.
    pub fn model(&self, a: u32, b: u32) -> Option<&ContactModel> {
        let n = self.names.len();
        self.models
            .get(a as usize * n + b as usize)
            .and_then(|m| m.as_ref())
    }

    /// Number of materials.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the table has no material.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Name of material `id`. Panics if `id` is not a material of the table.
    pub fn name(&self, id: u32) -> &str {
        &self.names[id as usize]
    }
}

/// Every body, wall, shape and material of a simulation, and the state kept between steps.
///
/// # Example
/// A sphere of radius 0.1 m dropped from 0.5 m onto a floor, built by hand and stepped with
/// [`step`](crate::world::step()) until it has bounced:
///
/// ```
/// use polydem::dynamics::{PrincipalInertia, RigidBody};
/// use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
/// use polydem::math::{Point, Pose, Vector};
/// use polydem::shape::{Plane, Shape, Sphere};
/// use polydem::world::{step, MaterialTable, StepParams, StepScratch, Wall, World};
///
/// // One material; an elastic linear law between it and itself.
/// let mut materials = MaterialTable::default();
/// let steel = materials.add_material("steel");
/// let model = ContactModel {
///     normal: NormalLaw::linear(1.0e7)?, // k_n (N/m)
///     damping: DampingLaw::None,
///     tangential: TangentialLaw::None,
/// };
/// materials.set_model(steel, steel, model);
/// let mut world = World::new(Vector::new(0.0, 0.0, -9.81), materials, 0.01);
///
/// // The floor: the half-space z ≤ 0 (outward normal +z).
/// let floor = Wall {
///     name: "floor".into(),
///     plane: Plane::new(Vector::z(), 0.0)?,
///     pose: Pose::identity(),
///     velocity: Vector::zeros(),
///     material: steel,
/// };
/// world.add_wall(floor)?;
///
/// // The ball: mass and inertia from the shape's volume properties and the density (kg/m³).
/// let sphere = Sphere::new(0.1)?;
/// let props = sphere.mass_properties();
/// let density = 7800.0;
/// let inertia = PrincipalInertia::new(props.principal_moments * density)?;
/// let ball = RigidBody::new_dynamic(Point::new(0.0, 0.0, 0.5), props.volume * density, inertia)?;
/// let shape = world.add_shape(Shape::Sphere(sphere));
/// world.add_body("ball", shape, steel, ball)?;
///
/// // Δt well below the contact time π √(m/k_n) ≈ 5.7 ms.
/// let params = StepParams::new(1.0e-4);
/// let mut scratch = StepScratch::default();
/// let mut lowest: f64 = 0.5;
/// for _ in 0..4000 {
///     step(&params, &mut world, &mut scratch)?;
///     lowest = lowest.min(world.body(0).position.z);
/// }
/// let ball = world.body(0);
/// assert!(lowest < 0.1, "the ball reached the floor (lowest centre {lowest} m)");
/// assert!(ball.velocity.z > 0.0 || ball.position.z > lowest, "and bounced");
/// // No damping, no friction: the mechanical energy is kept (the balance closes to the step's error).
/// let energy = world.energy();
/// assert!(energy.balance.abs() < 1e-3 * energy.mechanical().abs());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct World {
    /// The shapes the bodies refer to (by index).
    pub(in crate::world) shapes: Vec<Shape>,
    /// State of each body (pose, velocities, mass properties, motion).
    pub(in crate::world) bodies: Vec<RigidBody>,
    /// Index into `shapes` of each body's shape.
    pub(in crate::world) shape_of: Vec<u32>,
    /// Material id of each body.
    pub(in crate::world) material_of: Vec<u32>,
    /// Bounding-sphere radius of each body about its centre of mass (m).
    pub(in crate::world) radii: Vec<Real>,
    /// Name of each body.
    pub(in crate::world) names: Vec<String>,
    /// The walls (planes).
    pub(in crate::world) walls: Vec<Wall>,
    /// Materials and the contact law of each pair.
    pub(in crate::world) materials: MaterialTable,
    /// Gravitational acceleration (m/s²).
    pub(in crate::world) gravity: Vector,
    /// Persistent contacts with their history (tangential springs, solver caches).
    pub(in crate::world) contacts: ContactStore,
    /// Broad phase: grid, neighbour list and Verlet skin.
    pub(in crate::world) broad_phase: BroadPhase,
    /// Resultant loads of the last force evaluation.
    pub(in crate::world) loads: Loads,
    /// Energy dissipated and work done so far.
    pub(in crate::world) ledger: EnergyLedger,
    /// Which bodies are asleep (see [`super::sleeping`]); empty until the first step.
    pub(in crate::world) sleep: SleepState,
    /// Simulated time (s).
    pub(in crate::world) time: Real,
    /// Completed steps.
    pub(in crate::world) step_index: u64,
    /// The materials the bodies use, for the set-up checks (rebuilt after a checkpoint is read).
    #[serde(skip)]
    presence: MaterialPresence,
    /// In a part of a split world ([`super::distributed`]), the bodies it owns: its energy sums count
    /// those bodies and the pairs it answers for (the lower body owned). `None`: every body and pair.
    #[serde(skip)]
    pub(in crate::world) counted: Option<Vec<bool>>,
}

impl World {
    /// An empty world. `skin` (m) is the Verlet skin of the broad phase.
    pub fn new(gravity: Vector, materials: MaterialTable, skin: Real) -> Self {
        Self {
            shapes: Vec::new(),
            bodies: Vec::new(),
            shape_of: Vec::new(),
            material_of: Vec::new(),
            radii: Vec::new(),
            names: Vec::new(),
            walls: Vec::new(),
            materials,
            gravity,
            contacts: ContactStore::default(),
            broad_phase: BroadPhase::new(skin),
            loads: Loads::default(),
            ledger: EnergyLedger::default(),
            sleep: SleepState::default(),
            time: 0.0,
            step_index: 0,
            presence: MaterialPresence::default(),
            counted: None,
        }
    }

    /// Adds a shape to the table; returns its index.
    pub fn add_shape(&mut self, shape: Shape) -> u32 {
        self.shapes.push(shape);
        (self.shapes.len() - 1) as u32
    }

    /// Adds a body; returns its index. The body's material must have a law with every material already
    /// present, so that no pair can meet without one.
    pub fn add_body(
        &mut self,
        name: &str,
        shape: u32,
        material: u32,
        body: RigidBody,
    ) -> Result<u32, WorldError> {
        let radius = match self.shapes.get(shape as usize) {
            None => {
                return Err(WorldError::UnknownShape {
                    body: name.to_owned(),
                    shape: shape as usize,
                    count: self.shapes.len(),
                })
            }
            Some(Shape::Plane(_)) => {
                return Err(WorldError::PlaneBody {
                    body: name.to_owned(),
                })
            }
            Some(Shape::Polyhedron(p)) => p.bounding_radius(),
            Some(Shape::Sphere(s)) => s.radius(),
            Some(other) => other.convex().map_or(0.0, |c| c.bounding_radius()),
        };
        self.check_material(name, material, false)?;
        self.bodies.push(body);
        self.shape_of.push(shape);
        self.material_of.push(material);
        self.radii.push(radius);
        self.names.push(name.to_owned());
        self.loads.current = false;
        Ok((self.bodies.len() - 1) as u32)
    }

    /// Adds a wall; returns its index.
    pub fn add_wall(&mut self, wall: Wall) -> Result<u32, WorldError> {
        if !wall.velocity.iter().all(|v| v.is_finite()) {
            return Err(WorldError::NonFiniteWall {
                wall: wall.name.clone(),
                what: "velocity",
            });
        }
        if !wall.pose.translation.vector.iter().all(|v| v.is_finite()) {
            return Err(WorldError::NonFiniteWall {
                wall: wall.name.clone(),
                what: "position",
            });
        }
        self.check_material(&wall.name, wall.material, true)?;
        self.walls.push(wall);
        self.loads.current = false;
        Ok((self.walls.len() - 1) as u32)
    }

    /// The material exists and has a law with the material of every body already present, and, for a body,
    /// also with every wall and itself (walls never touch each other). The bodies' materials are read from
    /// the presence table ([`super::material_presence`]), one look-up per distinct material; a missing law
    /// is reported for the first body, then the first wall, that lacks one, as a scan of every body would.
    fn check_material(
        &mut self,
        owner: &str,
        material: u32,
        is_wall: bool,
    ) -> Result<(), WorldError> {
        if material as usize >= self.materials.len() {
            return Err(WorldError::UnknownMaterial {
                owner: owner.to_owned(),
                material: material as usize,
                count: self.materials.len(),
            });
        }
        self.presence.record(&self.material_of);
        let mut lookups = 0;
        let mut walls_read = 0;
        let lacks = |other: u32| self.materials.model(material, other).is_none();
        let mut missing = self.presence.present().iter().copied().find(|&other| {
            lookups += 1;
            lacks(other)
        });
        if missing.is_none() && !is_wall {
            missing = self.walls.iter().map(|w| w.material).find(|&other| {
                walls_read += 1;
                lookups += 1;
                lacks(other)
            });
        }
        if missing.is_none() && !is_wall {
            lookups += 1;
            missing = lacks(material).then_some(material);
        }
        let stats = &mut self.presence.stats;
        stats.law_lookups += lookups;
        stats.walls_read += walls_read;
        match missing {
            None => Ok(()),
            Some(other) => Err(WorldError::MissingLaw {
                owner: owner.to_owned(),
                a: self.materials.name(material).to_owned(),
                b: self.materials.name(other).to_owned(),
            }),
        }
    }

    /// The work the set-up checks of this world have done since it was made (or read from a checkpoint).
    pub fn setup_stats(&self) -> SetupStats {
        self.presence.stats
    }

    /// The pose of body `i` (body frame = the shape's principal frame → world).
    pub fn pose(&self, i: usize) -> Pose {
        let b = &self.bodies[i];
        Pose::from_parts(b.position.coords.into(), b.orientation)
    }

    /// The shape of body `i`.
    pub fn shape(&self, i: usize) -> &Shape {
        &self.shapes[self.shape_of[i] as usize]
    }

    /// Characteristic length of body `i` (m): its shape's length scale (bounding diameter).
    pub fn length_scale(&self, i: usize) -> Real {
        self.shape(i).length_scale().unwrap_or(2.0 * self.radii[i])
    }
}

impl World {
    /// The ledger at the current state. Before the first step the elastic potential is that of the last
    /// load evaluation, i.e. zero until one ran.
    pub fn energy(&self) -> EnergyReport {
        let (translational_kinetic, rotational_kinetic, gravitational_potential) =
            kinetic_and_gravity(self);
        let l = &self.ledger;
        let mut report = EnergyReport {
            time: self.time,
            translational_kinetic,
            rotational_kinetic,
            elastic_potential: self.loads.elastic_potential,
            gravitational_potential,
            dissipated_damping: l.dissipated_damping,
            dissipated_friction: l.dissipated_friction,
            dissipated_viscous: l.dissipated_viscous,
            external_work: l.external_work,
            tangential_stiffness_work: l.tangential_stiffness_work,
            balance: 0.0,
        };
        let initial = l.initial_total.unwrap_or_else(|| report.mechanical());
        report.balance = report.mechanical()
            + l.dissipated_damping
            + l.dissipated_friction
            + l.dissipated_viscous
            + l.removed_by_sleeping
            - l.external_work
            - l.tangential_stiffness_work
            - initial;
        report
    }

    /// Total linear momentum of the dynamic bodies (kg·m/s).
    pub fn linear_momentum(&self) -> Vector {
        self.bodies
            .iter()
            .filter(|b| b.is_dynamic())
            .map(|b| b.linear_momentum())
            .sum()
    }
}

/// Mechanical terms of the current state: (T_trans, T_rot, U_gravity) over the dynamic bodies counted
/// ([`World::counts_body`]).
fn kinetic_and_gravity(world: &World) -> (Real, Real, Real) {
    let (mut trans, mut rot, mut grav) = (0.0, 0.0, 0.0);
    for_each_counted_dynamic(world, |body| {
        trans += body.translational_kinetic_energy();
        rot += body.rotational_kinetic_energy();
        grav -= body.mass * world.gravity.dot(&body.position.coords);
    });
    (trans, rot, grav)
}

/// `f` on each dynamic body the world's energy sums count ([`World::counts_body`]), in body order.
#[inline]
fn for_each_counted_dynamic(world: &World, f: impl FnMut(&RigidBody)) {
    let dynamic = |b: &&RigidBody| b.is_dynamic();
    match world.counted.as_deref() {
        None => world.bodies.iter().filter(dynamic).for_each(f),
        Some(owned) => {
            let counted = world.bodies.iter().zip(owned).filter(|(_, &o)| o);
            counted.map(|(b, _)| b).filter(dynamic).for_each(f)
        }
    }
}

/// Σ c(m)|v|² over the dynamic bodies counted (W): the power of a global viscous damping.
pub(crate) fn viscous_power(world: &World, coefficient: impl Fn(Real) -> Real) -> Real {
    let mut power = 0.0;
    for_each_counted_dynamic(world, |b| {
        power += coefficient(b.mass) * b.velocity.norm_squared()
    });
    power
}
