//! One time step of the world, with its stages written out in order.
//!
//! ```text
//!  step n → n+1 (Δt):
//!   0. (first step only) evaluate the loads at the initial state       — the same stages 3–6 as below
//!   1. first half kick   v, L ← v, L + ½Δt (F_n, p_n)   with the loads kept from the previous evaluation
//!   2. drift             x, q ← x_{n+1}, q_{n+1}; walls move with their prescribed velocity
//!   3. broad phase       bounding spheres + Verlet skin → sorted body pairs; body–wall pairs by distance
//!   4. narrow phase      contact store synced to the candidate list; one contact query per candidate
//!   5. laws              ContactModel::evaluate per overlapping candidate (tangential history in the store)
//!   6. accumulate        per-body sums of forces and torques in candidate order (fixed, deterministic)
//!   7. second half kick  v, L ← v, L + ½Δt (F_{n+1}, p_{n+1})
//!   8. checks            non-finite state → StepError naming body and step; deep overlaps → StepReport
//!   9. ledger, counters
//! ```
//! Forces are evaluated once per step, at the new positions x_{n+1} (stages 3–6); the same loads close this
//! step (7) and open the next (1). The velocity-dependent parts (damping, tangential increment) see the
//! half-step velocities, as [`crate::dynamics::integrator`] documents.
//!
//! Every stage runs serially in the candidate order, which is a function of the state only (the broad
//! phase's sorted pairs, then body–wall pairs by body and wall). A parallel narrow phase and law stage can
//! produce per-candidate results in any order as long as stage 6 sums them in this order, which keeps runs
//! bit-identical for any thread count.

use std::time::{Duration, Instant};

use crate::contact::{
    query_with, ContactError, ContactGeometry, ContactKind, ContactTolerances, EpaScratch,
    QueryCounters,
};
use crate::dynamics::{Integrator, Motion, RotationScheme, TranslationParams, ViscousDamping};
use crate::law::{ContactKinematics, ContactResponse};
use crate::math::{Point, Real, Vector};
use crate::shape::Shape;

use super::contact_store::ContactKey;
use super::energy::viscous_power;
use super::world::World;

/// Default of [`StepParams::overlap_warning_fraction`]: 0.05. A DEM run with a stiffness that represents
/// the material keeps overlaps below ~1 % of the particle size; 5 % means the stiffness or the time step is
/// wrong for the impact speeds of the scene, well before the contact geometry itself degrades.
pub const DEFAULT_OVERLAP_WARNING_FRACTION: Real = 0.05;

/// Parameters of the step shared by all bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepParams {
    /// Time step Δt (s).
    pub dt: Real,
    /// Rotation scheme of the integrator.
    pub rotation: RotationScheme,
    /// Global viscous damping (paper eq. 6); accounted in the ledger as `dissipated_viscous`.
    pub damping: ViscousDamping,
    /// Tolerances of the contact queries.
    pub tolerances: ContactTolerances,
    /// A contact whose overlap exceeds this fraction of the smaller particle's length scale (bounding
    /// diameter) is reported in [`StepReport::overlap_warnings`].
    pub overlap_warning_fraction: Real,
}

impl StepParams {
    /// The step Δt with the paper's rotation scheme, no global damping, default tolerances and overlap
    /// warning fraction.
    pub fn new(dt: Real) -> Self {
        Self {
            dt,
            rotation: RotationScheme::default(),
            damping: ViscousDamping::None,
            tolerances: ContactTolerances::default(),
            overlap_warning_fraction: DEFAULT_OVERLAP_WARNING_FRACTION,
        }
    }
}

/// Buffers reused between steps; nothing in them matters after a step.
#[derive(Clone, Debug, Default)]
pub struct StepScratch {
    epa: EpaScratch,
    centres: Vec<Point>,
    candidates: Vec<ContactKey>,
    geometries: Vec<ContactGeometry>,
    responses: Vec<ContactResponse>,
}

/// Stage timers and counters of one or more steps (merge them with [`StepCounters::merge`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepCounters {
    pub steps: u64,
    pub broad: Duration,
    pub narrow: Duration,
    pub laws: Duration,
    pub accumulate: Duration,
    pub integrate: Duration,
    pub checks: Duration,
    /// Broad-phase grid rebuilds.
    pub broad_rebuilds: u64,
    /// Body pairs passed to the narrow phase (broad-phase candidates with at least one dynamic body).
    pub body_pairs_tested: u64,
    /// Body–wall pairs passed to the narrow phase, and those rejected by the bounding-sphere distance.
    pub wall_pairs_tested: u64,
    pub wall_pairs_rejected: u64,
    /// Overlapping contacts evaluated by the laws.
    pub contacts: u64,
    /// Contact-store entries created and dropped.
    pub contacts_created: u64,
    pub contacts_dropped: u64,
    /// Narrow-phase counters (queries by kind, GJK/EPA iterations, fallbacks).
    pub query: QueryCounters,
}

impl StepCounters {
    pub fn merge(&mut self, other: &StepCounters) {
        self.steps += other.steps;
        self.broad += other.broad;
        self.narrow += other.narrow;
        self.laws += other.laws;
        self.accumulate += other.accumulate;
        self.integrate += other.integrate;
        self.checks += other.checks;
        self.broad_rebuilds += other.broad_rebuilds;
        self.body_pairs_tested += other.body_pairs_tested;
        self.wall_pairs_tested += other.wall_pairs_tested;
        self.wall_pairs_rejected += other.wall_pairs_rejected;
        self.contacts += other.contacts;
        self.contacts_created += other.contacts_created;
        self.contacts_dropped += other.contacts_dropped;
        self.query.merge(&other.query);
    }

    /// Wall time of all stages.
    pub fn total_time(&self) -> Duration {
        self.broad + self.narrow + self.laws + self.accumulate + self.integrate + self.checks
    }
}

impl std::fmt::Display for StepCounters {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        writeln!(
            f,
            "stage times (ms): broad {:.1}, narrow {:.1}, laws {:.1}, accumulate {:.1}, integrate {:.1}, checks {:.1}",
            ms(self.broad),
            ms(self.narrow),
            ms(self.laws),
            ms(self.accumulate),
            ms(self.integrate),
            ms(self.checks)
        )?;
        writeln!(
            f,
            "steps {}, broad-phase rebuilds {}, body pairs tested {}, wall pairs tested {} (rejected by distance {}), contacts {}, store entries created {} dropped {}",
            self.steps,
            self.broad_rebuilds,
            self.body_pairs_tested,
            self.wall_pairs_tested,
            self.wall_pairs_rejected,
            self.contacts,
            self.contacts_created,
            self.contacts_dropped
        )?;
        write!(f, "{}", self.query)
    }
}

/// A contact deeper than the warning fraction of the particle size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlapWarning {
    pub key: ContactKey,
    /// Overlap δ_M (m).
    pub depth: Real,
    /// δ_M divided by the smaller particle's length scale.
    pub ratio: Real,
}

/// What one step observed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepReport {
    pub counters: StepCounters,
    /// Overlapping contacts at the end of the step.
    pub contacts: usize,
    /// The largest overlap / particle size at the end of the step.
    pub max_overlap_ratio: Real,
    pub overlap_warnings: Vec<OverlapWarning>,
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    #[error("step {step}: body {body} ('{name}') has a non-finite {quantity}")]
    NonFinite {
        step: u64,
        body: usize,
        name: String,
        quantity: &'static str,
    },
    #[error("step {step}: invalid time step {dt} s (must be finite and positive)")]
    InvalidTimeStep { step: u64, dt: Real },
    #[error("step {step}: contact query failed: {source}")]
    Contact {
        step: u64,
        #[source]
        source: ContactError,
    },
    #[error("step {step}: no contact law for materials {a} and {b}")]
    MissingLaw { step: u64, a: u32, b: u32 },
}

/// Advances the world by one step `params.dt` (see the module docs for the stages).
pub fn step(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
) -> Result<StepReport, StepError> {
    let dt = params.dt;
    if !(dt.is_finite() && dt > 0.0) {
        return Err(StepError::InvalidTimeStep {
            step: world.step_index,
            dt,
        });
    }
    let mut report = StepReport::default();
    let integrator = Integrator {
        translation: TranslationParams {
            gravity: world.gravity,
            damping: params.damping,
        },
        rotation: params.rotation,
    };
    // 0. The loads of the initial state (no tangential increment: no time has passed).
    if !world.loads.current {
        evaluate_loads(params, world, scratch, &mut report, 0.0)?;
        if world.ledger.initial_total.is_none() {
            world.ledger.initial_total = Some(world.energy().mechanical());
        }
    }
    let external_power_start = world.loads.external_power;
    let damping_power_start = world.loads.damping_power;
    let viscous_start = viscous_power(world, |m| params.damping.coefficient(m));

    // 1–2. First half kick with the kept loads, drift.
    let t = Instant::now();
    for (i, body) in world.bodies.iter_mut().enumerate() {
        integrator.first_half_kick(body, &world.loads.forces[i], &world.loads.torques[i], dt);
        integrator.drift(body, dt);
    }
    for wall in &mut world.walls {
        wall.pose.translation.vector += dt * wall.velocity;
    }
    report.counters.integrate += t.elapsed();

    // 3–6. Loads at the new positions.
    evaluate_loads(params, world, scratch, &mut report, dt)?;

    // 7. Second half kick.
    let t = Instant::now();
    for (i, body) in world.bodies.iter_mut().enumerate() {
        integrator.second_half_kick(body, &world.loads.forces[i], &world.loads.torques[i], dt);
    }
    report.counters.integrate += t.elapsed();

    // 8. Checks.
    let t = Instant::now();
    check_finite(world)?;
    report.counters.checks += t.elapsed();

    // 9. Ledger and counters.
    let viscous_end = viscous_power(world, |m| params.damping.coefficient(m));
    let ledger = &mut world.ledger;
    ledger.dissipated_damping += 0.5 * (damping_power_start + world.loads.damping_power) * dt;
    ledger.dissipated_friction += world.loads.friction_dissipation;
    ledger.dissipated_viscous += 0.5 * (viscous_start + viscous_end) * dt;
    ledger.external_work += 0.5 * (external_power_start + world.loads.external_power) * dt;
    world.time += dt;
    world.step_index += 1;
    report.counters.steps = 1;
    Ok(report)
}

/// Stages 3–6 at the current positions; `dt` is the tangential increment's time (0 at the initial state).
fn evaluate_loads(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    report: &mut StepReport,
    dt: Real,
) -> Result<(), StepError> {
    let step_index = world.step_index;
    let counters = &mut report.counters;

    // 3. Broad phase.
    let t = Instant::now();
    scratch.centres.clear();
    scratch
        .centres
        .extend(world.bodies.iter().map(|b| b.position));
    if world.broad_phase.update(&scratch.centres, &world.radii) {
        counters.broad_rebuilds += 1;
    }
    scratch.candidates.clear();
    for &(a, b) in world.broad_phase.pairs() {
        if world.bodies[a as usize].is_dynamic() || world.bodies[b as usize].is_dynamic() {
            scratch.candidates.push(ContactKey::Body { a, b });
        }
    }
    counters.body_pairs_tested += scratch.candidates.len() as u64;
    for (i, body) in world.bodies.iter().enumerate() {
        if !body.is_dynamic() {
            continue;
        }
        for (w, wall) in world.walls.iter().enumerate() {
            // A body whose bounding sphere does not reach the plane cannot touch it.
            if wall.signed_distance(&body.position) < world.radii[i] {
                scratch.candidates.push(ContactKey::Wall {
                    body: i as u32,
                    wall: w as u32,
                });
                counters.wall_pairs_tested += 1;
            } else {
                counters.wall_pairs_rejected += 1;
            }
        }
    }
    counters.broad += t.elapsed();

    // 4. Narrow phase.
    let t = Instant::now();
    // The store is taken out of the world for stages 4–5 so that the queries can read the bodies while
    // writing the per-pair state; it is put back before any return.
    let mut contacts = std::mem::take(&mut world.contacts);
    let sync = contacts.sync(&scratch.candidates, step_index);
    counters.contacts_created += sync.created as u64;
    counters.contacts_dropped += sync.dropped as u64;
    scratch.geometries.clear();
    for (key, state) in scratch
        .candidates
        .iter()
        .zip(contacts.states_mut().iter_mut())
    {
        let (pose_a, shape_a, pose_b, shape_b);
        let wall_shape;
        match *key {
            ContactKey::Body { a, b } => {
                pose_a = world.pose(a as usize);
                shape_a = world.shape(a as usize);
                pose_b = world.pose(b as usize);
                shape_b = world.shape(b as usize);
            }
            ContactKey::Wall { body, wall } => {
                let wall = &world.walls[wall as usize];
                wall_shape = Shape::Plane(wall.plane);
                pose_a = wall.pose;
                shape_a = &wall_shape;
                pose_b = world.pose(body as usize);
                shape_b = world.shape(body as usize);
            }
        }
        let g = match query_with(
            &pose_a,
            shape_a,
            &pose_b,
            shape_b,
            &params.tolerances,
            &mut state.cache,
            &mut scratch.epa,
            &mut counters.query,
        ) {
            Ok(g) => g,
            Err(source) => {
                world.contacts = contacts;
                return Err(StepError::Contact {
                    step: step_index,
                    source,
                });
            }
        };
        state.geometry = g;
        scratch.geometries.push(g);
    }
    counters.narrow += t.elapsed();

    // 5. Laws.
    let t = Instant::now();
    scratch.responses.clear();
    // The report describes the state at the end of the step: an initial evaluation's findings are
    // replaced by those of the step's own evaluation.
    report.contacts = 0;
    report.max_overlap_ratio = 0.0;
    report.overlap_warnings.clear();
    for ((key, g), state) in scratch
        .candidates
        .iter()
        .zip(&scratch.geometries)
        .zip(contacts.states_mut().iter_mut())
    {
        let (a_body, a_velocity_at, mat_a, b) = match *key {
            ContactKey::Body { a, b } => (Some(a as usize), None, world.material_of[a as usize], b),
            ContactKey::Wall { body, wall } => {
                let w = &world.walls[wall as usize];
                (None, Some(w.velocity), w.material, body)
            }
        };
        let b = b as usize;
        let mat_b = world.material_of[b];
        let Some(model) = world.materials.model(mat_a, mat_b) else {
            world.contacts = contacts;
            return Err(StepError::MissingLaw {
                step: step_index,
                a: mat_a,
                b: mat_b,
            });
        };
        if g.kind != ContactKind::Overlap {
            // The law resets the history of a pair that does not overlap.
            state.history = Default::default();
            state.force_on_b = Vector::zeros();
            scratch.responses.push(ContactResponse::default());
            continue;
        }
        let body_b = &world.bodies[b];
        let (velocity_a, center_a, effective_mass, scale) = match a_body {
            Some(a) => {
                let body_a = &world.bodies[a];
                let m = match (body_a.is_dynamic(), body_b.is_dynamic()) {
                    (true, true) => body_a.mass * body_b.mass / (body_a.mass + body_b.mass),
                    (true, false) => body_a.mass,
                    _ => body_b.mass,
                };
                let scale = world.length_scale(a).min(world.length_scale(b));
                (body_a.velocity_at(&g.point), body_a.position, m, scale)
            }
            None => (
                a_velocity_at.unwrap_or_else(Vector::zeros),
                g.point_a,
                body_b.mass,
                world.length_scale(b),
            ),
        };
        let kinematics = ContactKinematics {
            relative_velocity: body_b.velocity_at(&g.point) - velocity_a,
            effective_mass,
            center_a,
            center_b: body_b.position,
            dt,
        };
        let model = model.for_shapes(a_body.map(|a| world.shape(a)), world.shape(b));
        let response = model.evaluate(g, &kinematics, &mut state.history);
        state.force_on_b = response.force_on_b;
        scratch.responses.push(response);
        report.contacts += 1;
        let ratio = g.depth / scale;
        report.max_overlap_ratio = report.max_overlap_ratio.max(ratio);
        if ratio > params.overlap_warning_fraction {
            report.overlap_warnings.push(OverlapWarning {
                key: *key,
                depth: g.depth,
                ratio,
            });
        }
    }
    world.contacts = contacts;
    counters.contacts += report.contacts as u64;
    counters.laws += t.elapsed();

    // 6. Accumulate, in candidate order.
    let t = Instant::now();
    let n = world.bodies.len();
    let loads = &mut world.loads;
    loads.forces.clear();
    loads.forces.resize(n, Vector::zeros());
    loads.torques.clear();
    loads.torques.resize(n, Vector::zeros());
    loads.wall_forces.clear();
    loads.wall_forces.resize(world.walls.len(), Vector::zeros());
    loads.elastic_potential = 0.0;
    loads.damping_power = 0.0;
    loads.friction_dissipation = 0.0;
    for (key, r) in scratch.candidates.iter().zip(&scratch.responses) {
        match *key {
            ContactKey::Body { a, b } => {
                loads.forces[a as usize] -= r.force_on_b;
                loads.torques[a as usize] += r.torque_on_a;
                loads.forces[b as usize] += r.force_on_b;
                loads.torques[b as usize] += r.torque_on_b;
            }
            ContactKey::Wall { body, wall } => {
                loads.wall_forces[wall as usize] -= r.force_on_b;
                loads.forces[body as usize] += r.force_on_b;
                loads.torques[body as usize] += r.torque_on_b;
            }
        }
        loads.elastic_potential += r.normal_potential + r.tangential_potential;
        loads.damping_power += r.damping_power;
        loads.friction_dissipation += r.friction_dissipation;
    }
    // Power delivered to the system by everything that moves without responding to forces.
    let mut external_power = 0.0;
    for (i, body) in world.bodies.iter().enumerate() {
        if let Motion::Prescribed { .. } = body.motion {
            external_power -= loads.forces[i].dot(&body.velocity)
                + loads.torques[i].dot(&body.angular_velocity());
        }
    }
    for (w, wall) in world.walls.iter().enumerate() {
        external_power -= loads.wall_forces[w].dot(&wall.velocity);
    }
    loads.external_power = external_power;
    loads.current = true;
    counters.accumulate += t.elapsed();
    Ok(())
}

/// Stage 8: every dynamic body's state and loads are finite.
fn check_finite(world: &World) -> Result<(), StepError> {
    let finite = |v: &Vector| v.iter().all(|x| x.is_finite());
    for (i, body) in world.bodies.iter().enumerate() {
        let quantity = if !finite(&world.loads.forces[i]) {
            Some("contact force")
        } else if !finite(&world.loads.torques[i]) {
            Some("contact torque")
        } else if !finite(&body.position.coords) {
            Some("position")
        } else if !finite(&body.velocity) {
            Some("velocity")
        } else if !body.orientation.coords.iter().all(|x| x.is_finite()) {
            Some("orientation")
        } else if !finite(&body.angular_momentum) {
            Some("angular momentum")
        } else {
            None
        };
        if let Some(quantity) = quantity {
            return Err(StepError::NonFinite {
                step: world.step_index + 1,
                body: i,
                name: world.names[i].clone(),
                quantity,
            });
        }
    }
    Ok(())
}
