//! One time step of the world, with its stages written out in order.
//!
//! ```text
//!  step n → n+1 (Δt):
//!   0. (first step only) evaluate the loads at the initial state       — the same stages 3–6 as below
//!   1. first half kick   v, L ← v, L + ½Δt (F_n, p_n)   with the loads kept from the previous evaluation
//!   2. drift             x, q ← x_{n+1}, q_{n+1}; walls move with their prescribed velocity
//!   3. broad phase       bounding spheres + Verlet skin → sorted body pairs; body–wall pairs by distance
//!   4. narrow phase      contact store synced to the candidate list; one contact query per candidate
//!   5. laws              ContactModel::evaluate per overlapping candidate (tangential history in the store);
//!                        4 and 5 run fused, one pass over the candidates (the store entry is in cache)
//!   6. accumulate        per-body sums of forces and torques in candidate order (fixed, deterministic:
//!                        a scatter on one thread, a gather per body over its pairs on several)
//!  6b. (sleeping on) wake the sleeping bodies whose load departs from their rest load, or that touch a
//!      moving wall or a prescribed body
//!   7. second half kick  v, L ← v, L + ½Δt (F_{n+1}, p_{n+1}); on several threads without sleeping or
//!                        prescribed bodies, each body's sums of stage 6 are taken in this pass, just before
//!                        its kick (one parallel region fewer; the same additions)
//!   8. checks            non-finite state → StepError naming body and step; deep overlaps → StepReport
//!                        (7 and the body checks of 8 run fused, one pass over the bodies)
//!  8b. (sleeping on) calm counters, bodies falling asleep (see [`super::sleeping`])
//!   9. ledger, counters
//! ```
//! Forces are evaluated once per step, at the new positions x_{n+1} (stages 3–6); the same loads close this
//! step (7) and open the next (1). The velocity-dependent parts (damping, tangential increment) see the
//! half-step velocities, as [`crate::dynamics::integrator`] documents.
//!
//! The candidate order is a function of the state only (the broad phase's sorted pairs, then body–wall
//! pairs by body and wall). Stages 4 and 5 (one query and one law evaluation per candidate), the force sums
//! of stage 6 (one body at a time, over its pairs in candidate order) and the integration (1–2, 7–8; one
//! body at a time) run on rayon's current thread pool when the scene is large enough ([`Parallelism`]);
//! each computes a result per item into that item's own slot, and the sums over all candidates (energy
//! terms, report) are taken serially in candidate order, so a run is bit-identical for any number of
//! threads (see [`super::parallel`]; `tests/world_parallel.rs`).

use std::time::{Duration, Instant};

use crate::contact::{
    contact_plane_sphere, contact_sphere_sphere, query_with, ContactError, ContactKind,
    ContactTolerances, QueryCounters,
};
use crate::dynamics::rotation::{drift_isotropic, is_isotropic};
use crate::dynamics::translation::drift_position;
use crate::dynamics::{Integrator, Motion, RotationScheme, TranslationParams, ViscousDamping};
use crate::law::{ContactKinematics, ContactModel, DampingLaw, TangentialLaw};
use crate::math::{Point, Real, Vector};
use crate::shape::Shape;

use super::body_inputs;
use super::contact_store::BodyAdjacency;
use super::contact_store::{ContactKey, ContactState};
use super::energy::{external_power, ContactWork, LastForces, StepPowers};
use super::parallel::{
    for_each_chunked, for_each_item3_checked, for_each_item4, for_each_item_checked,
    for_each_item_pair, integration_work, Parallelism, Worker,
};
use super::region_profile::{self, Section};
use super::skips::{self, Skips};
use super::sleeping::{self, SleepParams};
use super::sphere_kernel;
use super::sphere_step;
use super::world::World;

/// Default of [`StepParams::overlap_warning_fraction`]: 0.05. A DEM run with a stiffness that represents
/// the material keeps overlaps below ~1 % of the particle size; 5 % means the stiffness or the time step is
/// wrong for the impact speeds of the scene, well before the contact geometry itself degrades.
pub const DEFAULT_OVERLAP_WARNING_FRACTION: Real = 0.05;

/// Parameters of the step shared by all bodies.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// From which sizes the stages run on several threads (results are identical either way).
    pub parallel: Parallelism,
    /// Work skipped because the scene does not need it (all on by default; see [`super::skips`]).
    pub skips: Skips,
    /// Freezing of bodies at rest (off by default; see [`super::sleeping`]).
    pub sleeping: SleepParams,
    /// Whether the step books the per-contact terms of the energy ledger (damping, friction and
    /// tangential stiffness work; see [`super::energy`]). On by default. Off, the step skips that booking
    /// (a run that only needs trajectories and forces: the speed comparisons with codes that keep no
    /// ledger); bodies, forces and the contact store are the same bits either way, but the ledger's
    /// `dissipated_damping`, `dissipated_friction` and `tangential_stiffness_work` stay where they were, so
    /// [`World::energy`]'s balance no longer closes.
    pub energy_ledger: bool,
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
            parallel: Parallelism::default(),
            skips: Skips::default(),
            sleeping: SleepParams::default(),
            energy_ledger: true,
        }
    }
}

/// Buffers reused between steps; nothing in them matters after a step.
#[derive(Clone, Debug, Default)]
pub struct StepScratch {
    /// Per-body inputs of stage 3 (written by the drift pass) and the kept candidate list's key; its
    /// summary's anisotropic count (dynamic bodies with unequal principal moments at the last evaluation
    /// of the loads) chooses serial or parallel integration (never a result).
    pub(super) inputs: body_inputs::BodyInputs,
    /// Whether some body has a prescribed motion (its power enters the ledger).
    any_prescribed: bool,
    /// The contact model of each material pair with the skips applied.
    models: Vec<Option<ContactModel>>,
    candidates: Vec<ContactKey>,
    pub(super) evaluated: Vec<Evaluated>,
    /// One per chunk of the parallel stages (see [`super::parallel`]).
    workers: Vec<Worker>,
    /// The summed contributions of the frozen contacts (see [`super::sleeping`]).
    frozen: sleeping::FrozenLoads,
    /// Per body, what the sphere path of stages 4–5 reads (see [`super::sphere_kernel`]).
    spheres: Vec<sphere_kernel::SphereBody>,
    /// Set by stage 6 when it left the per-body force sums to the pass of stages 7–8 (the gather fused
    /// with the second half kick); consumed in the same step.
    pub(super) deferred_gather: bool,
}

/// Stage timers and counters of one or more steps (merge them with [`StepCounters::merge`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepCounters {
    pub steps: u64,
    pub broad: Duration,
    /// The fused narrow phase and laws (one pass over the candidates).
    pub narrow: Duration,
    /// Zero since the laws run fused with the narrow phase (their time is in `narrow`); kept so that the
    /// summaries keep their columns.
    pub laws: Duration,
    pub accumulate: Duration,
    /// Stages 1–2 and 7–8 (the checks run fused with the second half kick).
    pub integrate: Duration,
    /// Zero since the checks run fused with the second half kick (their time is in `integrate`); kept so
    /// that the summaries keep their columns.
    pub checks: Duration,
    /// The part of the stage times spent in sections that run on one thread whatever the pool: the
    /// bookkeeping around the parallel regions (per-body inputs, candidate list, store sync, grid build,
    /// sums in candidate order) and every region that stays below its [`Parallelism`] threshold. On one
    /// thread, `serial / total_time()` is the serial fraction of Amdahl's law for that scene (the
    /// single-thread scatter of the forces counts here, the gather that replaces it on several threads
    /// does not: a slight overestimate).
    pub serial: Duration,
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
    /// Candidates not re-evaluated because frozen (both sides asleep or fixed; see [`super::sleeping`]).
    pub frozen_pairs: u64,
    /// Bodies that fell asleep and that were woken; sleeping bodies summed over the steps.
    pub fell_asleep: u64,
    pub woken: u64,
    pub sleeping_body_steps: u64,
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
        self.serial += other.serial;
        self.broad_rebuilds += other.broad_rebuilds;
        self.body_pairs_tested += other.body_pairs_tested;
        self.wall_pairs_tested += other.wall_pairs_tested;
        self.wall_pairs_rejected += other.wall_pairs_rejected;
        self.contacts += other.contacts;
        self.contacts_created += other.contacts_created;
        self.contacts_dropped += other.contacts_dropped;
        self.frozen_pairs += other.frozen_pairs;
        self.fell_asleep += other.fell_asleep;
        self.woken += other.woken;
        self.sleeping_body_steps += other.sleeping_body_steps;
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
            "stage times (ms): broad {:.1}, narrow {:.1}, laws {:.1}, accumulate {:.1}, integrate {:.1}, checks {:.1}; on one thread whatever the pool {:.1}",
            ms(self.broad),
            ms(self.narrow),
            ms(self.laws),
            ms(self.accumulate),
            ms(self.integrate),
            ms(self.checks),
            ms(self.serial)
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
        if self.frozen_pairs + self.fell_asleep + self.sleeping_body_steps > 0 {
            writeln!(
                f,
                "sleeping: frozen pairs {}, bodies fell asleep {}, woken {}, sleeping body-steps {}",
                self.frozen_pairs, self.fell_asleep, self.woken, self.sleeping_body_steps
            )?;
        }
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

impl StepError {
    /// The error for the first body with a non-finite `quantity` found by the checks of stages 7–8, in
    /// the step being taken.
    pub(super) fn non_finite(world: &World, (body, quantity): (usize, &'static str)) -> Self {
        StepError::NonFinite {
            step: world.step_index + 1,
            body,
            name: world.names[body].clone(),
            quantity,
        }
    }
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
    world.sleep.resize(world.bodies.len());
    if !params.sleeping.enabled && world.sleep.sleeping > 0 {
        // Sleeping switched off: every body wakes.
        report.counters.woken += world.sleep.wake_all() as u64;
    }
    let integrator = Integrator {
        translation: TranslationParams {
            gravity: world.gravity,
            damping: params.damping,
        },
        rotation: params.rotation,
    };
    // 0. The loads of the initial state (no tangential increment: no time has passed).
    if !world.loads.current {
        evaluate_loads(params, world, scratch, &mut report, 0.0, false)?;
        if world.ledger.initial_total.is_none() {
            world.ledger.initial_total = Some(world.energy().mechanical());
        }
    }
    if sphere_step::applies(params, world) {
        return sphere_step::step_spheres(params, world, scratch, report);
    }
    let powers = StepPowers::at_start(params.damping, world);

    // 1–2. First half kick with the kept loads, drift.
    let t = Instant::now();
    let parallel_bodies = integration_work(world.bodies.len(), scratch.inputs.summary.anisotropic)
        >= params.parallel.min_bodies;
    let (loads, asleep) = (&world.loads, &world.sleep);
    let skip = params.skips;
    let splitting = match params.rotation {
        RotationScheme::Splitting { sub_rotation } => Some(sub_rotation),
        _ => None,
    };
    // The drift pass also writes what stage 3 reads of each body (centre, flags; see [`super::body_inputs`]).
    let inputs = &mut scratch.inputs;
    inputs.resize(world.bodies.len());
    inputs.resize_omegas(world.bodies.len());
    let (at_build, limit_sq) = (
        world.broad_phase.centres_at_build(),
        world.broad_phase.rebuild_limit_sq(),
    );
    let kick_drift = |i: usize, body: &mut crate::dynamics::RigidBody| {
        if asleep.is_asleep(i) || (skip.non_dynamic_pairs && is_at_rest_fixed(body)) {
            return;
        }
        integrator.first_half_kick(body, &loads.forces[i], &loads.torques[i], dt);
        if let (Some(form), true) = (splitting, body.is_dynamic()) {
            if skip.still_rotation && body.angular_momentum == Vector::zeros() {
                // Zero angular momentum: the rotation sub-flows are identities (see `skips`).
                drift_position(body, dt);
                return;
            }
            if skip.isotropic_rotation && is_isotropic(&body.inertia.0) {
                // Equal principal moments: the free rotation is one turn about L (see `skips`).
                drift_position(body, dt);
                let moment = body.inertia.0.x;
                drift_isotropic(
                    form,
                    &mut body.orientation,
                    &body.angular_momentum,
                    moment,
                    dt,
                );
                return;
            }
        }
        integrator.drift(body, dt);
    };
    region_profile::region(Section::KickDrift, || {
        for_each_item4(
            parallel_bodies,
            &mut world.bodies,
            &mut inputs.centres,
            &mut inputs.flags,
            &mut inputs.omegas,
            |i, body, centre, flags, omega| {
                kick_drift(i, body);
                *centre = body.position;
                *flags = body_inputs::flags_of(i, body, at_build, limit_sq);
                *omega = body_inputs::omega_of(body, skip.isotropic_rotation);
            },
        )
    });
    inputs.fresh = true;
    inputs.omegas_fresh = true;
    for wall in &mut world.walls {
        wall.pose.translation.vector += dt * wall.velocity;
    }
    let elapsed = t.elapsed();
    report.counters.integrate += elapsed;
    if !parallel_bodies {
        report.counters.serial += elapsed;
    }

    // 3–6. Loads at the new positions (without sleeping, the per-body sums of a parallel evaluation are
    // left to the pass of 7–8: one parallel region fewer).
    evaluate_loads(
        params,
        world,
        scratch,
        &mut report,
        dt,
        !params.sleeping.enabled,
    )?;

    // 6b. Sleeping bodies disturbed by this evaluation wake before the second half kick.
    if params.sleeping.enabled {
        report.counters.woken += sleeping::wake_disturbed(world);
    }

    // 7–8. Second half kick, then the checks of the same body, in one pass (the first non-finite body in
    // body order is reported, for any number of threads).
    let t = Instant::now();
    let parallel_bodies = integration_work(world.bodies.len(), scratch.inputs.summary.anisotropic)
        >= params.parallel.min_bodies;
    let non_finite = if std::mem::take(&mut scratch.deferred_gather) {
        // Stage 6's per-body sums, fused with 7–8: body i's force and torque over its pairs in candidate
        // order (the same additions as the gather of stage 6), then its kick and checks.
        let n_bodies = world.bodies.len();
        let adjacency = region_profile::serial(Section::SerialStore, || {
            world.contacts.body_adjacency(n_bodies)
        });
        report.counters.serial += t.elapsed();
        let (evaluated, asleep) = (&scratch.evaluated, &world.sleep);
        let loads = &mut world.loads;
        region_profile::region(Section::KickChecks, || {
            for_each_item3_checked(
                true,
                &mut world.bodies,
                &mut loads.forces,
                &mut loads.torques,
                |i, body, force, torque| {
                    sum_body_loads(adjacency, evaluated, i, force, torque);
                    if !(asleep.is_asleep(i) || (skip.non_dynamic_pairs && is_at_rest_fixed(body)))
                    {
                        integrator.second_half_kick(body, force, torque, dt);
                    }
                    non_finite_quantity(body, force, torque)
                },
            )
        })
    } else {
        let (loads, asleep) = (&world.loads, &world.sleep);
        let non_finite = region_profile::region(Section::KickChecks, || {
            for_each_item_checked(parallel_bodies, &mut world.bodies, |i, body| {
                if !(asleep.is_asleep(i) || (skip.non_dynamic_pairs && is_at_rest_fixed(body))) {
                    integrator.second_half_kick(body, &loads.forces[i], &loads.torques[i], dt);
                }
                non_finite_quantity(body, &loads.forces[i], &loads.torques[i])
            })
        });
        if !parallel_bodies {
            report.counters.serial += t.elapsed();
        }
        non_finite
    };
    report.counters.integrate += t.elapsed();
    if let Some(found) = non_finite {
        return Err(StepError::non_finite(world, found));
    }

    // 8b. Sleeping: calm counters, falling asleep (serial, in body order).
    if params.sleeping.enabled {
        let counts = sleeping::update(&params.sleeping, world);
        report.counters.fell_asleep += counts.fell_asleep;
        report.counters.woken += counts.woken;
    }
    report.counters.sleeping_body_steps += world.sleep.sleeping as u64;

    // 9. Ledger and counters.
    powers.close_step(params.damping, dt, world);
    report.counters.steps = 1;
    Ok(report)
}

/// Stages 3–6 at the current positions; `dt` is the tangential increment's time (0 at the initial state).
pub(super) fn evaluate_loads(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    report: &mut StepReport,
    dt: Real,
    defer_gather: bool,
) -> Result<(), StepError> {
    let step_index = world.step_index;
    let counters = &mut report.counters;
    // The angular velocities of this step's drift pass, if it ran (consumed first: never read stale).
    let omegas_fresh = std::mem::take(&mut scratch.inputs.omegas_fresh);

    // 3. Broad phase.
    let t = Instant::now();
    let profile_inputs = region_profile::serial_start();
    // Per-body inputs of the stages below (centres for the broad phase, flags: dynamic, anisotropic,
    // prescribed, moved half the skin), written by this step's drift pass, else here (the initial
    // evaluation), then folded (see [`super::body_inputs`]).
    let inputs = &mut scratch.inputs;
    if !std::mem::take(&mut inputs.fresh) {
        inputs.write(&world.bodies, &world.broad_phase);
    }
    inputs.summarise();
    let summary = inputs.summary;
    let broad = &mut world.broad_phase;
    // A body beyond half the skin does not rebuild by itself: the lists stay valid while the two largest
    // moves sum to less than the skin (`BroadPhase::pairs_may_be_stale`, scanned only then).
    let rebuild = !params.skips.verlet_skin
        || broad.rebuilds() == 0
        || broad.centres_at_build().len() != inputs.centres.len()
        || broad.walls_moved(&world.walls)
        || (summary.any_far && broad.pairs_may_be_stale(&inputs.centres, &world.walls));
    region_profile::serial_end(Section::SerialInputs, profile_inputs);
    if rebuild {
        broad.rebuild_with_walls(&inputs.centres, &world.radii, &world.walls);
        counters.broad_rebuilds += 1;
    }
    let profile_inputs = region_profile::serial_start();
    // The candidate list: kept from the last step unless the grid was rebuilt or a dynamic flag changed.
    inputs.update_candidates(
        broad,
        params.skips.non_dynamic_pairs,
        &mut scratch.candidates,
    );
    counters.body_pairs_tested += inputs.body_candidates as u64;
    let wall_pairs = inputs.wall_candidates as u64;
    counters.wall_pairs_tested += wall_pairs;
    counters.wall_pairs_rejected += summary.dynamic as u64 * world.walls.len() as u64 - wall_pairs;
    scratch.any_prescribed = summary.any_prescribed;
    // The contact models of every material pair with the skips applied, once per step.
    let n_materials = world.materials.len();
    scratch.models.clear();
    for a in 0..n_materials as u32 {
        for b in 0..n_materials as u32 {
            let model = world.materials.model(a, b);
            scratch
                .models
                .push(model.map(|m| effective_model(m, &params.skips)));
        }
    }
    region_profile::serial_end(Section::SerialInputs, profile_inputs);
    let elapsed = t.elapsed();
    counters.broad += elapsed;
    counters.serial += elapsed.saturating_sub(world.broad_phase.take_parallel_search_time());

    // 4–5. Narrow phase and laws, fused: per candidate, the contact query then (if the shapes overlap) the
    // law, in one pass over the store (in parallel, each candidate writing its own store entry and result
    // slot). Frozen candidates keep their last geometry and force (see [`super::sleeping`]).
    let t = Instant::now();
    // The store is taken out of the world for stages 4–5 so that the queries can read the bodies while
    // writing the per-pair state; it is put back before any return.
    let mut contacts = std::mem::take(&mut world.contacts);
    let t_sync = Instant::now();
    let sync = region_profile::serial(Section::SerialStore, || {
        contacts.sync_tagged(
            &scratch.candidates,
            scratch.inputs.candidates_tag,
            step_index,
        )
    });
    counters.serial += t_sync.elapsed();
    counters.contacts_created += sync.created as u64;
    counters.contacts_dropped += sync.dropped as u64;
    let store_changed = sync.created + sync.dropped > 0;
    let n_candidates = scratch.candidates.len();
    let parallel = n_candidates >= params.parallel.min_candidates;
    // Every slot's flags are overwritten below (the rest only for overlapping pairs): no clearing.
    scratch.evaluated.resize(n_candidates, Evaluated::default());
    let world_ref: &World = world;
    let candidates = &scratch.candidates;
    // The sphere path: its per-body inputs, gathered once (see [`super::sphere_kernel`]).
    let spheres = (params.skips.sphere_kernel
        && sphere_kernel::gather(
            world_ref,
            params.skips.isotropic_rotation,
            world_ref.bodies.len() >= params.parallel.min_bodies
                && rayon::current_num_threads() > 1,
            &mut scratch.spheres,
        ))
    .then_some(scratch.spheres.as_slice());
    let pair = PairInputs {
        world: world_ref,
        isotropic: params.skips.isotropic_rotation,
        omegas: omegas_fresh.then_some(scratch.inputs.omegas.as_slice()),
        models: &scratch.models,
        n_materials,
        dt,
        step_index,
        ledger: params.energy_ledger,
    };
    // Every evaluated candidate that stage 6 has to sum is listed (serially, in candidate order, there).
    let pick = |i: usize, out: &Evaluated, worker: &mut Worker| {
        if out.contributes() {
            worker.picked.push(i as u32);
        }
    };
    let t_parallel = Instant::now();
    let evaluated = region_profile::region(Section::Narrow, || {
        for_each_chunked(
            parallel,
            contacts.states_mut(),
            &mut scratch.evaluated,
            &mut scratch.workers,
            |i, state, out, worker| {
                let key = candidates[i];
                if sleeping::is_frozen_entry(world_ref, key, state) {
                    // Kept from its last evaluation and summed in `scratch.frozen` (stage 6).
                    out.frozen = true;
                    out.overlapping = false;
                    // Frozen bodies do not move: no work.
                    out.work = ContactWork::default();
                    worker.tally += 1;
                    return Ok(());
                }
                // The last contact point, for the ledger of a pair that opens in this step.
                let previous_point = state.geometry.point;
                if let Some(spheres) = spheres {
                    if let Some(done) = sphere_kernel::evaluate(
                        params,
                        &pair,
                        spheres,
                        key,
                        state,
                        &previous_point,
                        out,
                        worker,
                    ) {
                        done?;
                        pick(i, out, worker);
                        return Ok(());
                    }
                }
                narrow_phase(params, world_ref, key, state, worker).map_err(|source| {
                    StepError::Contact {
                        step: step_index,
                        source,
                    }
                })?;
                contact_law(&pair, key, state, &previous_point, out)?;
                pick(i, out, worker);
                Ok(())
            },
        )
    });
    if !parallel {
        counters.serial += t_parallel.elapsed();
    }
    for worker in &mut scratch.workers {
        counters.query.merge(&worker.query);
        worker.query = QueryCounters::default();
        counters.frozen_pairs += worker.tally;
    }
    world.contacts = contacts;
    evaluated?;
    counters.narrow += t.elapsed();

    // 6. Accumulate, in candidate order, with the report (the state at the end of the step: an initial
    // evaluation's findings are replaced by those of the step's own evaluation), in one pass.
    let t = Instant::now();
    let profile_sums = region_profile::serial_start();
    report.contacts = 0;
    report.max_overlap_ratio = 0.0;
    report.overlap_warnings.clear();
    let n = world.bodies.len();
    if world.sleep.sleeping > 0 {
        scratch
            .frozen
            .ensure(world, store_changed, params.overlap_warning_fraction);
    }
    let loads = &mut world.loads;
    let gather = parallel && rayon::current_num_threads() > 1;
    if !gather {
        // The scatter below adds into zeros; the gather writes every body's slot (no clearing pass).
        loads.forces.clear();
        loads.torques.clear();
    }
    loads.forces.resize(n, Vector::zeros());
    loads.torques.resize(n, Vector::zeros());
    loads.wall_forces.clear();
    loads.wall_forces.resize(world.walls.len(), Vector::zeros());
    loads.elastic_potential = 0.0;
    loads.damping_work = 0.0;
    loads.friction_dissipation = 0.0;
    loads.tangential_stiffness_work = 0.0;
    // Forces and torques on the bodies, summed in candidate order: on one thread by a scatter over the
    // candidates (in the loop below: one sequential pass); on several per body over its pairs (the same
    // additions in the same order: the same bits; it reads each result twice, so it pays only in parallel).
    // The sums can wait for the pass of stages 7–8 when nothing reads the loads before it: no frozen
    // contributions to add, no prescribed body's power (below), no sleeping check (the caller's choice).
    scratch.deferred_gather =
        gather && defer_gather && !scratch.any_prescribed && world.sleep.sleeping == 0;
    let mut gather_time = Duration::ZERO;
    if gather && !scratch.deferred_gather {
        // The rows are rebuilt (serially) after a sync that changed the keys.
        let adjacency = world.contacts.body_adjacency(n);
        let t_gather = Instant::now();
        let evaluated = &scratch.evaluated;
        region_profile::region(Section::Gather, || {
            for_each_item_pair(
                true,
                &mut loads.forces,
                &mut loads.torques,
                |i, force, torque| sum_body_loads(adjacency, evaluated, i, force, torque),
            )
        });
        gather_time = t_gather.elapsed();
    }
    // The serial sums visit only the candidates stages 4–5 picked (overlapping, or with ledger terms: a
    // pair that opens in this step books its release), in candidate order: the others would add nothing
    // (their ledger terms are ±0, and a sum that starts at +0 is unchanged by adding ±0), so the sums have
    // the same bits as over all candidates, for any number of threads (see [`Worker::picked`]).
    let picked = scratch.workers.iter().flat_map(|w| &w.picked);
    for &i in picked {
        let (key, e) = (
            &scratch.candidates[i as usize],
            &scratch.evaluated[i as usize],
        );
        loads.damping_work += e.work.damping;
        loads.friction_dissipation += e.work.friction;
        loads.tangential_stiffness_work += e.work.stiffness;
        if !e.overlapping {
            // A separated pair contributes nothing (its response slot is stale).
            continue;
        }
        report.contacts += 1;
        report.max_overlap_ratio = report.max_overlap_ratio.max(e.overlap_ratio);
        if e.overlap_ratio > params.overlap_warning_fraction {
            report.overlap_warnings.push(OverlapWarning {
                key: *key,
                depth: e.depth,
                ratio: e.overlap_ratio,
            });
        }
        let r = e;
        match *key {
            ContactKey::Body { a, b } if !gather => {
                loads.forces[a as usize] -= r.force_on_b;
                loads.torques[a as usize] += r.torque_on_a;
                loads.forces[b as usize] += r.force_on_b;
                loads.torques[b as usize] += r.torque_on_b;
            }
            ContactKey::Body { .. } => {}
            ContactKey::Wall { body, wall } => {
                loads.wall_forces[wall as usize] -= r.force_on_b;
                if !gather {
                    loads.forces[body as usize] += r.force_on_b;
                    loads.torques[body as usize] += r.torque_on_b;
                }
            }
        }
        loads.elastic_potential += r.potential;
    }
    // The frozen contacts, summed once while the sleeping set and the store's pairs stay the same, added
    // after the candidates in both summation modes (the same bits on any number of threads).
    if world.sleep.sleeping > 0 {
        let f = &scratch.frozen;
        f.add_to(&mut loads.forces, &mut loads.torques);
        for (w, force) in loads.wall_forces.iter_mut().zip(&f.wall_forces) {
            *w += force;
        }
        loads.elastic_potential += f.potential;
        report.contacts += f.contacts;
        report.max_overlap_ratio = report.max_overlap_ratio.max(f.max_overlap_ratio);
        report
            .overlap_warnings
            .extend(f.deep.iter().map(|c| OverlapWarning {
                key: c.key,
                depth: c.depth,
                ratio: c.overlap_ratio,
            }));
    }
    counters.contacts += report.contacts as u64;
    // Power delivered to the system by everything that moves without responding to forces.
    let prescribed = if scratch.any_prescribed {
        world.bodies.as_slice()
    } else {
        &[]
    };
    loads.external_power = external_power(loads, prescribed, &world.walls);
    loads.current = true;
    region_profile::serial_end(Section::SerialSums, profile_sums);
    let elapsed = t.elapsed();
    counters.accumulate += elapsed;
    counters.serial += elapsed.saturating_sub(gather_time);
    Ok(())
}

/// Stage 6 for body `i`: the sum of the forces and torques of its overlapping pairs, in candidate order
/// (side A receives the opposite of the force on B and the torque on A).
#[inline]
pub(super) fn sum_body_loads(
    adjacency: &BodyAdjacency,
    evaluated: &[Evaluated],
    i: usize,
    force: &mut Vector,
    torque: &mut Vector,
) {
    let (mut f, mut t) = (Vector::zeros(), Vector::zeros());
    for &entry in adjacency.row(i) {
        let e = &evaluated[(entry & !BodyAdjacency::SIDE_A) as usize];
        if !e.overlapping {
            continue;
        }
        if entry & BodyAdjacency::SIDE_A != 0 {
            f -= e.force_on_b;
            t += e.torque_on_a;
        } else {
            f += e.force_on_b;
            t += e.torque_on_b;
        }
    }
    *force = f;
    *torque = t;
}

impl Evaluated {
    /// The slot of a candidate that does not overlap and books no ledger term (what [`contact_law`] writes
    /// for it).
    #[inline(always)]
    pub(super) fn clear_separated(&mut self) {
        self.frozen = false;
        self.work = ContactWork::default();
        self.overlapping = false;
    }

    /// The slot of an overlapping candidate without ledger terms (what [`overlap_law`] writes for it with
    /// the ledger off): the response's loads and potential, the overlap and its ratio to the size.
    #[inline(always)]
    pub(super) fn set_overlapping(
        &mut self,
        response: &crate::law::ContactResponse,
        depth: Real,
        overlap_ratio: Real,
    ) {
        self.frozen = false;
        self.work = ContactWork::default();
        self.force_on_b = response.force_on_b;
        self.torque_on_a = response.torque_on_a;
        self.torque_on_b = response.torque_on_b;
        self.potential = response.normal_potential + response.tangential_potential;
        self.overlapping = true;
        self.depth = depth;
        self.overlap_ratio = overlap_ratio;
    }

    /// Whether stage 6 has something to sum for this candidate: a force, or a nonzero ledger term.
    #[inline]
    fn contributes(&self) -> bool {
        self.overlapping
            || self.work.damping != 0.0
            || self.work.friction != 0.0
            || self.work.stiffness != 0.0
    }
}

/// The result of stage 5 for one candidate. The flags and `work` are written for every candidate; the
/// other fields only when `overlapping` (a separated pair contributes no force, and no stage reads them).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Evaluated {
    /// What stage 6 reads of the law's [`crate::law::ContactResponse`]: the force on B, the torques on A
    /// and B, and the elastic potential (normal + tangential, J).
    force_on_b: Vector,
    torque_on_a: Vector,
    torque_on_b: Vector,
    potential: Real,
    /// The ledger terms of this step (nonzero for a separated pair only in the step it opens).
    work: ContactWork,
    /// Whether the shapes overlap (the law produced a force).
    overlapping: bool,
    /// Whether the pair is frozen (kept from its last evaluation; see [`super::sleeping`]).
    frozen: bool,
    /// Overlap δ_M (m) and δ_M divided by the smaller particle's length scale.
    depth: Real,
    overlap_ratio: Real,
}

/// What stages 4–5 read for every candidate, gathered once per step.
pub(super) struct PairInputs<'a> {
    pub(super) world: &'a World,
    /// Whether ω of a body with equal principal moments is taken as L/J (the `isotropic_rotation` skip).
    isotropic: bool,
    /// Every body's ω as [`body_inputs::omega_of`] gives it, when the drift pass wrote them this step.
    omegas: Option<&'a [Vector]>,
    /// The contact model of each material pair (row-major `n_materials²`), with the skips applied.
    models: &'a [Option<ContactModel>],
    n_materials: usize,
    pub(super) dt: Real,
    step_index: u64,
    /// Whether the ledger terms are booked ([`StepParams::energy_ledger`]).
    pub(super) ledger: bool,
}

impl PairInputs<'_> {
    pub(super) fn model(&self, mat_a: u32, mat_b: u32) -> Result<&ContactModel, StepError> {
        self.models[mat_a as usize * self.n_materials + mat_b as usize]
            .as_ref()
            .ok_or(StepError::MissingLaw {
                step: self.step_index,
                a: mat_a,
                b: mat_b,
            })
    }

    /// Velocity (m/s) of the material point of body `i` at `point` (world): [`RigidBody::velocity_at`],
    /// with ω = L/J for a body with equal principal moments when the skip is on (ω = R J̄⁻¹ Rᵀ L = L/J
    /// when J̄ = J·I; see `skips`).
    ///
    /// [`RigidBody::velocity_at`]: crate::dynamics::RigidBody::velocity_at
    #[inline]
    fn velocity_at(&self, i: usize, point: &Point) -> Vector {
        let body = &self.world.bodies[i];
        let omega = match self.omegas {
            Some(omegas) => omegas[i],
            None => body_inputs::omega_of(body, self.isotropic),
        };
        body.velocity + omega.cross(&(point - body.position))
    }

    /// v_B − v_A (m/s) at `point` for the pair `key` (A a wall: its prescribed velocity), with each
    /// body's lever arm taken from its centre `back` seconds earlier (x − back·v: the centre before this
    /// step's drift when `back` = Δt, so the lever arm with which the last forces were applied).
    fn relative_velocity(&self, key: ContactKey, point: &Point, back: Real) -> Vector {
        let at = |i: usize| self.velocity_at(i, &(point + back * self.world.bodies[i].velocity));
        match key {
            ContactKey::Body { a, b } => at(b as usize) - at(a as usize),
            ContactKey::Wall { body, wall } => {
                at(body as usize) - self.world.walls[wall as usize].velocity
            }
        }
    }
}

/// Stage 4 for one candidate: the contact query between its two shapes (A = body a or the wall, B = body b),
/// written to `state.geometry`. Sphere–sphere and wall–sphere pairs call their closed forms directly with
/// the body positions (the dispatcher's own cases, without building the poses: the same values).
#[inline]
fn narrow_phase(
    params: &StepParams,
    world: &World,
    key: ContactKey,
    state: &mut ContactState,
    worker: &mut Worker,
) -> Result<(), ContactError> {
    let tol = &params.tolerances;
    let (pose_a, shape_a, pose_b, shape_b);
    let wall_shape;
    match key {
        ContactKey::Body { a, b } => {
            let (a, b) = (a as usize, b as usize);
            shape_a = world.shape(a);
            shape_b = world.shape(b);
            let (xa, xb) = (&world.bodies[a].position, &world.bodies[b].position);
            if params.skips.bounding_spheres {
                if let Some(g) = skips::reject_by_bounding_spheres(
                    xa,
                    world.radii[a],
                    xb,
                    world.radii[b],
                    shape_a
                        .length_scale()
                        .unwrap_or(0.0)
                        .max(shape_b.length_scale().unwrap_or(0.0)),
                    tol,
                    &mut worker.query,
                ) {
                    state.geometry = g;
                    return Ok(());
                }
            }
            if let (Shape::Sphere(sa), Shape::Sphere(sb)) = (shape_a, shape_b) {
                worker.query.sphere_sphere += 1;
                state.geometry = contact_sphere_sphere(xa, sa.radius(), xb, sb.radius(), tol);
                worker.query.record(&state.geometry);
                return Ok(());
            }
            pose_a = world.pose(a);
            pose_b = world.pose(b);
            if let Some((pa, pb)) = skips::polyhedra(shape_a, shape_b) {
                if skips::polyhedron_pair(
                    &params.skips,
                    (&pose_a, pa),
                    (&pose_b, pb),
                    tol,
                    state,
                    &mut worker.epa,
                    &mut worker.query,
                ) {
                    return Ok(());
                }
            }
        }
        ContactKey::Wall { body, wall } => {
            let wall = &world.walls[wall as usize];
            let body = body as usize;
            if params.skips.bounding_spheres {
                // The wall list has a skin: a body listed may still be beyond its radius from the plane.
                let x = &world.bodies[body].position;
                if let Some(g) = skips::reject_wall_by_bounding_sphere(
                    wall.signed_distance(x),
                    &wall.normal_world(),
                    x,
                    world.radii[body],
                    &mut worker.query,
                ) {
                    state.geometry = g;
                    return Ok(());
                }
            }
            if let Shape::Sphere(s) = world.shape(body) {
                worker.query.sphere_plane += 1;
                state.geometry = contact_plane_sphere(
                    &wall.pose,
                    wall.plane.normal(),
                    wall.plane.offset(),
                    &world.bodies[body].position,
                    s.radius(),
                    tol,
                );
                worker.query.record(&state.geometry);
                return Ok(());
            }
            wall_shape = Shape::Plane(wall.plane);
            pose_a = wall.pose;
            shape_a = &wall_shape;
            pose_b = world.pose(body);
            shape_b = world.shape(body);
        }
    }
    state.geometry = query_with(
        &pose_a,
        shape_a,
        &pose_b,
        shape_b,
        tol,
        &mut state.cache,
        &mut worker.epa,
        &mut worker.query,
    )?;
    Ok(())
}

/// Stage 5 for one candidate: the pair's contact model on the geometry of stage 4 (stored in `state`),
/// updating the tangential history and the stored forces; the result goes to `out`. `previous_point` is
/// the contact point of the pair's last evaluation (the ledger of a pair that opens needs it).
#[inline]
pub(super) fn contact_law(
    pair: &PairInputs,
    key: ContactKey,
    state: &mut ContactState,
    previous_point: &Point,
    out: &mut Evaluated,
) -> Result<(), StepError> {
    out.frozen = false;
    let ContactState {
        geometry: g,
        history,
        force_on_b,
        damping_force,
        ..
    } = state;
    if g.kind != ContactKind::Overlap {
        out.work = ContactWork::default();
        let previous = LastForces {
            damping_force: *damping_force,
            history: *history,
        };
        if pair.ledger && !previous.is_zero() {
            // The pair opened in this step: its last forces acted for the first half kick.
            let world = pair.world;
            let (shape_a, mat_a, b) = match key {
                ContactKey::Body { a, b } => (
                    Some(world.shape(a as usize)),
                    world.material_of[a as usize],
                    b,
                ),
                ContactKey::Wall { body, wall } => {
                    (None, world.walls[wall as usize].material, body)
                }
            };
            let b = b as usize;
            let model = pair
                .model(mat_a, world.material_of[b])?
                .for_shapes(shape_a, world.shape(b));
            let relative_velocity = pair.relative_velocity(key, previous_point, pair.dt);
            out.work = ContactWork::of_release(&model, &previous, &relative_velocity, pair.dt);
        }
        // The law resets the history of a pair that does not overlap.
        *history = Default::default();
        *force_on_b = Vector::zeros();
        *damping_force = Vector::zeros();
        out.overlapping = false;
        return Ok(());
    }
    let world = pair.world;
    let (a_body, a_velocity_at, mat_a, b) = match key {
        ContactKey::Body { a, b } => (Some(a as usize), None, world.material_of[a as usize], b),
        ContactKey::Wall { body, wall } => {
            let w = &world.walls[wall as usize];
            (None, Some(w.velocity), w.material, body)
        }
    };
    let b = b as usize;
    let model = pair.model(mat_a, world.material_of[b])?;
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
            (pair.velocity_at(a, &g.point), body_a.position, m, scale)
        }
        None => (
            a_velocity_at.unwrap_or_else(Vector::zeros),
            g.point_a,
            body_b.mass,
            world.length_scale(b),
        ),
    };
    let kinematics = ContactKinematics {
        relative_velocity: pair.velocity_at(b, &g.point) - velocity_a,
        effective_mass,
        center_a,
        center_b: body_b.position,
        dt: pair.dt,
    };
    let model = model.for_shapes(a_body.map(|a| world.shape(a)), world.shape(b));
    overlap_law(
        pair,
        state,
        || pair.relative_velocity(key, previous_point, pair.dt),
        &model,
        &kinematics,
        scale,
        out,
    );
    Ok(())
}

/// The end of stage 5 for an overlapping candidate whose model (with the pair's stiffnesses), kinematics
/// and length scale (the smaller particle's) are known: the law, the ledger terms, the stored forces.
/// `previous_velocity` gives v_B − v_A at the last contact point with the last lever arms (called only
/// when the ledger books the last forces: [`PairInputs::relative_velocity`] with `back` = Δt).
#[inline]
pub(super) fn overlap_law(
    pair: &PairInputs,
    state: &mut ContactState,
    previous_velocity: impl FnOnce() -> Vector,
    model: &ContactModel,
    kinematics: &ContactKinematics,
    scale: Real,
    out: &mut Evaluated,
) {
    let ContactState {
        geometry: g,
        history,
        force_on_b,
        damping_force,
        ..
    } = state;
    let previous = LastForces {
        damping_force: *damping_force,
        history: *history,
    };
    let response = model.evaluate(g, kinematics, history);
    out.work = if !pair.ledger {
        ContactWork::default()
    } else if previous.is_zero() {
        ContactWork::of_new_contact(&response, &kinematics.relative_velocity, pair.dt)
    } else {
        // The last forces were applied with the lever arms of the last contact point.
        ContactWork::of_evaluation(
            &previous,
            &previous_velocity(),
            &g.normal,
            &response,
            &kinematics.relative_velocity,
            pair.dt,
        )
    };
    *force_on_b = response.force_on_b;
    *damping_force = response.damping_force;
    out.force_on_b = response.force_on_b;
    out.torque_on_a = response.torque_on_a;
    out.torque_on_b = response.torque_on_b;
    out.potential = response.normal_potential + response.tangential_potential;
    out.overlapping = true;
    out.depth = g.depth;
    out.overlap_ratio = g.depth / scale;
}

/// The model with the slots the skips make free: no tangential spring when μ = 0, no damping term when its
/// coefficient is 0 (see [`super::skips`]).
pub(super) fn effective_model(model: &ContactModel, skips: &Skips) -> ContactModel {
    let mut m = *model;
    if skips.frictionless_history && m.tangential.stiffness_and_friction(0.0).1 == 0.0 {
        m.tangential = TangentialLaw::None;
    }
    if skips.undamped_contacts {
        if let DampingLaw::Viscous { coefficient } | DampingLaw::Dashpot { coefficient } = m.damping
        {
            if coefficient == 0.0 {
                m.damping = DampingLaw::None;
            }
        }
    }
    m
}

/// A fixed body whose velocities are already zero: integrating it changes nothing.
fn is_at_rest_fixed(body: &crate::dynamics::RigidBody) -> bool {
    matches!(body.motion, Motion::Fixed)
        && body.velocity == Vector::zeros()
        && body.angular_momentum == Vector::zeros()
}

/// Stage 8 for one body: the first non-finite quantity of its loads and state, if any.
pub(super) fn non_finite_quantity(
    body: &crate::dynamics::RigidBody,
    force: &Vector,
    torque: &Vector,
) -> Option<&'static str> {
    first_non_finite(
        force,
        torque,
        &body.position,
        &body.velocity,
        &body.orientation,
        &body.angular_momentum,
    )
}

/// The first non-finite quantity among a body's loads and state, in the order the step's error names
/// them; shared by the general step and the sphere paths so all report the same quantity.
///
/// First one sum of them all, formed as a tree of vector sums: finite only if every term is (inf − inf
/// and NaN propagate), so a finite sum answers `None` at once; otherwise the quantities are tested one
/// by one (which also clears a sum that overflowed from finite terms). Every body of every step takes
/// the test: as a chain of 18 scalar additions the sum took ~5 % of a step of the flat sphere path
/// (`perf record`, bed c, 2026-11-23), and before that the general step tested the quantities one by
/// one.
#[inline(always)]
pub(super) fn first_non_finite(
    force: &Vector,
    torque: &Vector,
    position: &Point,
    velocity: &Vector,
    orientation: &crate::math::Rotation,
    angular_momentum: &Vector,
) -> Option<&'static str> {
    let sum = ((force + torque) + (position.coords + velocity) + angular_momentum).sum()
        + orientation.coords.sum();
    if sum.is_finite() {
        return None;
    }
    first_non_finite_one_by_one(
        force,
        torque,
        position,
        velocity,
        orientation,
        angular_momentum,
    )
}

#[cold]
#[inline(never)]
fn first_non_finite_one_by_one(
    force: &Vector,
    torque: &Vector,
    position: &Point,
    velocity: &Vector,
    orientation: &crate::math::Rotation,
    angular_momentum: &Vector,
) -> Option<&'static str> {
    let finite = |v: &Vector| v.iter().all(|x| x.is_finite());
    if !finite(force) {
        Some("contact force")
    } else if !finite(torque) {
        Some("contact torque")
    } else if !finite(&position.coords) {
        Some("position")
    } else if !finite(velocity) {
        Some("velocity")
    } else if !orientation.coords.iter().all(|x| x.is_finite()) {
        Some("orientation")
    } else if !finite(angular_momentum) {
        Some("angular momentum")
    } else {
        None
    }
}
