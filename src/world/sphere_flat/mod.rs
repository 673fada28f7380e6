//! The flat sphere path: a world of free spheres stepped from compact per-sphere arrays and a half
//! neighbour list, the way LAMMPS/LIGGGHTS step granular spheres, with the physics of the general step.
//!
//! # What it is
//! [`SphereSim::from_world`] copies a world whose bodies are all free spheres (dynamic, equal principal
//! moments) into a [`SphereSim`] that owns, for the length of a run:
//! - per sphere, in arrays: centre, velocity and angular velocity (the pair loop's record, 72 bytes),
//!   angular momentum and orientation (the integration's), radius, mass, moment and material, and the
//!   last evaluation's force and torque;
//! - the walls (planes; fixed or moving with their prescribed velocity) and their last forces;
//! - a half neighbour list with a Verlet skin (the world's broad-phase skin) and a body–wall list, each
//!   pair's tangential spring stored beside it and carried across rebuilds (`neighbours`); nothing is
//!   stored for a separated pair but its cleared spring and a flag;
//! - the time, step index and energy ledger of the world, and with the ledger on, per listed pair the
//!   last damping force and contact point it books from (`ledger`).
//!
//! [`SphereSim::step`] advances it by one step with the stages of the general step for free spheres
//! (`super::sphere_step`): first half kick, drift (leapfrog translation, one turn about L for the
//! orientation), walls moved, lists rebuilt when the two largest displacements since the build sum to the
//! skin, the pair loop (closed-form geometry and the laws of [`crate::law`], `pair`), per-body sums, the
//! second half kick and the finiteness checks; [`SphereSim::run_steps`] runs many, holding the pool's
//! threads for the run (`crew`). [`SphereSim::write_back`] puts the state back into the
//! world (bodies, walls, loads, ledger, time, and a contact store with every listed pair's spring and
//! last forces), so that checkpoints, outputs and the general step continue from it.
//!
//! # The same bits as the general step
//! Every value is computed by the same operations in the same order as the general step: the kick,
//! drift and turn of `super::sphere_step`, the closed forms and inlined law of `super::sphere_kernel`
//! (the same models with the step's skips applied), and the per-body sums over the overlapping pairs in
//! the order of the general contact keys (for body i: pairs (a, i) by increasing a, then (i, b) by
//! increasing b, then its walls; a pair that does not overlap adds nothing on either path, so which
//! separated pairs a list holds does not matter). So bodies, loads and springs are the same bits as the
//! general step's (`tests/sphere_flat_paths.rs`), for any number of threads: every parallel pass
//! computes one result per sphere or pair into its own slot, and the only sums across items (wall
//! forces, elastic potential, the ledger's contact terms) are taken serially in pair order.
//! The per-contact terms of the energy ledger (damping, friction and tangential stiffness work) are
//! booked by the pair loop with the general step's functions and summed in its candidate order
//! (`ledger`; `tests/sphere_flat_ledger.rs`).
//!
//! # When it applies (else [`NotSphereOnly`])
//! Every body a dynamic sphere with equal principal moments; the splitting rotation with the
//! `isotropic_rotation` and `still_rotation` skips; no global viscous damping; sleeping off and nobody
//! asleep. The energy ledger may be on or off (`energy_ledger`): on, the path books the contact terms as
//! the general step does; off, it books none, as the general step does not either. Its cost on sphere
//! bed a (5000 steps, one thread): ~1.43 s with the ledger against ~1.15 s without (+24 %; the general
//! step with the ledger ~3.1 s), nearly all of it in the pair loop (the terms need the law's slip and
//! stiffness work, the velocity at the last contact point and the last forces of each contact).
//!
//! # Cost (callgrind instructions, one thread)
//! The first 1000 steps of sphere beds a / b / c (`examples/sphere_bed_speed.rs`, run under
//! `valgrind --tool=callgrind --toggle-collect='*run_flat*'`) take 1481 / 1774 / 1206 instructions per
//! particle-step, with the scenes' LIGGGHTS projection of the spring
//! ([`crate::law::SpringRotation::Projection`]) and their 0.5 mm skin (LIGGGHTS' `neighbor`: bed b
//! rebuilds its lists 71 times per 1000 steps, a and c 11). Where they go: the pair loop (~80 % of bed a:
//! ~3.7 listed pairs and ~2.3 overlapping ones per sphere), list rebuilds (bed b: ~3800 instructions per
//! sphere and build, ~16 % of its instructions: the fast bed spheres the projectile throws use up the
//! skin), integration. In time (`examples/sphere_bed_speed`, 5000 steps, one thread, release build) bed a
//! takes 1.31–1.51 s, b 2.19–2.35 s, c 1.08–1.17 s; `perf record` of bed a puts ~73 % of the samples in
//! the pair loop and ~17 % in the kicks and drift.
//!
//! # Validity of the owned state
//! From [`SphereSim::from_world`] on, the simulation owns the state: the world it came from is stale
//! until [`SphereSim::write_back`]. Its broad phase is reset by the write-back (the general step rebuilds
//! its lists on its next step), and its contact store then holds the flat list's pairs, with the geometry
//! the general step would have stored for them at the current positions.

mod blocks;
mod crew;
mod fused;
mod isa;
mod ledger;
mod neighbours;
mod pair;
mod passes;
mod run;
mod step;
mod team;

use super::step::guard::Guard;
use crate::contact::QueryCounters;
use crate::dynamics::rotation::{is_isotropic, SubRotation};
use crate::dynamics::{Motion, RotationScheme, ViscousDamping};
use crate::law::ContactModel;
use crate::math::{Point, Real, Rotation, Vector};
use crate::shape::Shape;
use rayon::prelude::*;

use super::broad_phase::BroadPhase;
use super::contact_store::{ContactKey, ContactState, ContactStore};
use super::energy::{ContactWork, EnergyLedger};
use super::step::{
    effective_models, sphere_pair_geometry, wall_sphere_geometry, StepError, StepParams,
};
use super::world::{Wall, World};

pub use blocks::TeamSplit;
pub use neighbours::{NeighbourList, LARGE_RADIUS_FACTOR, MAX_CELLS_PER_BODY};
use neighbours::{SpareVec, NOT_CARRIED};
use pair::{Kinematic, PairConstants, PairOut, Props, WallConstants, WallPlane};

/// Why a world cannot take the flat sphere path (see the module docs).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotSphereOnly {
    /// A body is not a sphere.
    #[error("body {body} ('{name}') is not a sphere")]
    NotASphere {
        /// Index of the body.
        body: usize,
        /// Name of the body.
        name: String,
    },
    /// A body is not dynamic (fixed or prescribed).
    #[error("body {body} ('{name}') is not a free (dynamic) body")]
    NotDynamic {
        /// Index of the body.
        body: usize,
        /// Name of the body.
        name: String,
    },
    /// A body's principal moments of inertia are not equal.
    #[error("body {body} ('{name}') has unequal principal moments")]
    Anisotropic {
        /// Index of the body.
        body: usize,
        /// Name of the body.
        name: String,
    },
    /// The step parameters use something the path does not implement.
    #[error("the flat sphere path needs {what}")]
    Params {
        /// What the path needs.
        what: &'static str,
    },
}

/// The angular part of a sphere's state, read by the integration only.
#[derive(Clone, Copy, Debug)]
struct Spin {
    angular_momentum: Vector,
    orientation: Rotation,
}

/// A world of free spheres stepped on the flat path (see the module docs for the state it owns).
#[derive(Clone, Debug)]
pub struct SphereSim {
    params: StepParams,
    form: SubRotation,
    kin: Vec<Kinematic>,
    spin: Vec<Spin>,
    props: Vec<Props>,
    /// Contact force and torque of the last evaluation on each sphere.
    force: Vec<Vector>,
    torque: Vec<Vector>,
    names: Vec<String>,
    gravity: Vector,
    walls: Vec<Wall>,
    planes: Vec<WallPlane>,
    wall_forces: Vec<Vector>,
    models: Vec<Option<ContactModel>>,
    n_materials: usize,
    list: NeighbourList,
    /// Per listed body pair, r_a + r_b (m) and the constants of the pair loop; per listed wall pair, its
    /// constants (formed after every build of the lists, aligned with them).
    reach: Vec<Real>,
    pair_constants: Vec<PairConstants>,
    wall_constants: Vec<WallConstants>,
    /// The vectors of the constants of the build before (refilled by the next build).
    spare_reach: SpareVec<Real>,
    spare_constants: SpareVec<PairConstants>,
    /// Whether the drift turns the orientations (see [`SphereSim::set_track_orientation`]).
    track_orientation: bool,
    /// How the team's threads share a step's work (see [`SphereSim::set_team_split`]).
    split: TeamSplit,
    /// The threads' speeds the blocks are made for.
    speeds: blocks::ThreadSpeeds,
    /// Whether the passes run in their x86-64-v3 build (see [`SphereSim::set_wide_instructions`]).
    v3: bool,
    /// The pair loop's blocks (made for the current lists and pool).
    blocks: blocks::Blocks,
    /// The last evaluation of every listed pair (aligned with the lists); valid when `outs_valid`.
    out: Vec<PairOut>,
    wall_out: Vec<PairOut>,
    /// Whether `out` holds the evaluation that produced `force` (false until this simulation evaluated
    /// the pairs: the loads were taken from the world).
    outs_valid: bool,
    /// The world's elastic potential when the loads were taken from it.
    start_potential: Real,
    external_power: Real,
    ledger: EnergyLedger,
    /// Per listed pair, what the energy ledger books (empty when it is off; [`ledger`]).
    pair_ledger: ledger::PairLedger,
    /// The contact terms of the ledger booked by the last step (zero when it is off).
    step_work: ContactWork,
    time: Real,
    step_index: u64,
    /// What the check of the time step keeps of the world (`super::step::guard`).
    guard: Guard,
}

impl SphereSim {
    /// The flat simulation of `world` stepped with `params` (see the module docs). When the world's loads
    /// are not current (no step taken yet), the initial loads are evaluated here, as the general step's
    /// stage 0 does (with its ledger's initial total).
    pub fn from_world(world: &World, params: &StepParams) -> Result<Self, StepFlatError> {
        let form = flat_sub_rotation(world, params)?;
        let FlatBodies { kin, spin, props } = flat_bodies(world)?;
        let n = world.bodies.len();
        let mut models = Vec::new();
        effective_models(&world.materials, &params.skips, &mut models);
        let planes: Vec<WallPlane> = world.walls.iter().map(WallPlane::of).collect();
        let mut sim = Self {
            params: *params,
            form,
            kin,
            spin,
            props,
            force: vec![Vector::zeros(); n],
            torque: vec![Vector::zeros(); n],
            names: world.names.clone(),
            gravity: world.gravity,
            walls: world.walls.clone(),
            planes,
            wall_forces: vec![Vector::zeros(); world.walls.len()],
            models,
            n_materials: world.materials.len(),
            list: NeighbourList::new(world.broad_phase.skin()),
            reach: Vec::new(),
            pair_constants: Vec::new(),
            spare_reach: SpareVec::default(),
            spare_constants: SpareVec::default(),
            wall_constants: Vec::new(),
            track_orientation: true,
            split: TeamSplit::default(),
            speeds: blocks::ThreadSpeeds::default(),
            v3: isa::v3(),
            blocks: blocks::Blocks::default(),
            out: Vec::new(),
            wall_out: Vec::new(),
            outs_valid: false,
            start_potential: world.loads.elastic_potential,
            external_power: world.loads.external_power,
            ledger: world.ledger,
            pair_ledger: ledger::PairLedger::default(),
            step_work: ContactWork::default(),
            time: world.time,
            step_index: world.step_index,
            guard: Guard::of(world, params.dt),
        };
        sim.first_build(world);
        sim.initial_loads(world)?;
        // The pair loop's blocks for the pool this is made on (so that its first step can already run
        // as one job of the team: `fused`).
        sim.ready_blocks();
        Ok(sim)
    }

    /// The first build of the lists, importing the springs (and, with the ledger, the last forces) of
    /// the world's contact store; then the pairs' constants.
    fn first_build(&mut self, world: &World) {
        let store = &world.contacts;
        let import = |body: Option<(u32, u32)>, wall: Option<(u32, u32)>| {
            let key = match (body, wall) {
                (Some((a, b)), _) => ContactKey::Body { a, b },
                (None, Some((body, wall))) => ContactKey::Wall { body, wall },
                (None, None) => return None,
            };
            store.get(&key).map(|s| (s.history, s.since_step))
        };
        let centres: Vec<Point> = self.kin.iter().map(|k| k.position).collect();
        let parallel = self.parallel_bodies();
        self.list.rebuild(
            &centres,
            &self.props,
            &self.planes,
            parallel,
            world.step_index,
            &import,
        );
        if self.params.energy_ledger {
            self.pair_ledger.carry(&mut self.list, None, Some(store));
        }
        self.prepare_pairs(parallel);
    }

    /// The world's loads when they are current; else stage 0's: the loads of the initial state with no
    /// tangential increment, and the ledger's initial total, as the general step forms them.
    fn initial_loads(&mut self, world: &World) -> Result<(), StepFlatError> {
        if world.loads.current && world.loads.forces.len() == self.kin.len() {
            self.force.clone_from(&world.loads.forces);
            self.torque.clone_from(&world.loads.torques);
            if world.loads.wall_forces.len() == world.walls.len() {
                self.wall_forces.clone_from(&world.loads.wall_forces);
            }
            return Ok(());
        }
        let found = self.evaluate(0.0)?;
        self.gather_only(found.scattered);
        // The general step books no term of the initial evaluation either.
        self.pair_ledger.take_sums();
        if self.ledger.initial_total.is_none() {
            let mut at_start = world.clone();
            at_start.loads.forces.clone_from(&self.force);
            at_start.loads.torques.clone_from(&self.torque);
            at_start.loads.elastic_potential = self.elastic_potential();
            self.ledger.initial_total = Some(at_start.energy().mechanical());
        }
        Ok(())
    }

    /// Forms the constants of every listed pair (after a build of the lists).
    fn prepare_pairs(&mut self, parallel: bool) {
        let (list, props, models, n_materials) =
            (&self.list, &self.props, &self.models, self.n_materials);
        let tol = &self.params.tolerances;
        let model = |a: u32, b: u32| models[a as usize * n_materials + b as usize].as_ref();
        let body = |p: usize| {
            let (pa, pb) = (&props[list.a[p] as usize], &props[list.b[p] as usize]);
            (
                pa.radius + pb.radius,
                PairConstants::of(
                    pa,
                    pb,
                    list.root_radius[p],
                    list.effective_mass[p],
                    model(pa.material, pb.material),
                    tol,
                ),
            )
        };
        let n = list.a.len();
        // A pair listed before keeps its constants (functions of its two bodies: the same bits).
        let (old_reach, old_constants) = (
            std::mem::take(&mut self.reach),
            std::mem::take(&mut self.pair_constants),
        );
        let carried = |p: usize| {
            let k = list.carried_from[p] as usize;
            match (old_reach.get(k), old_constants.get(k)) {
                (Some(&reach), Some(&c)) if list.carried_from[p] != NOT_CARRIED => (reach, c),
                _ => body(p),
            }
        };
        let (mut reach, mut constants) = (
            neighbours::recycled(&mut self.spare_reach.0),
            neighbours::recycled(&mut self.spare_constants.0),
        );
        if parallel && n >= MIN_PARALLEL_PAIRS {
            (0..n)
                .into_par_iter()
                .map(carried)
                .unzip_into_vecs(&mut reach, &mut constants);
        } else {
            for (r, c) in (0..n).map(carried) {
                reach.push(r);
                constants.push(c);
            }
        }
        (self.reach, self.pair_constants) = (reach, constants);
        (self.spare_reach.0, self.spare_constants.0) = (old_reach, old_constants);
        self.wall_constants = list
            .wall_body
            .iter()
            .zip(&list.wall_of)
            .map(|(&i, &w)| {
                let p = &props[i as usize];
                WallConstants::of(p, model(self.planes[w as usize].material, p.material), tol)
            })
            .collect();
    }

    /// Whether the drift turns each sphere's orientation (on by default). A sphere's orientation enters
    /// no force, torque or motion of this path (the spheres are isotropic: the angular velocity is L/J
    /// whatever the orientation), so with tracking off the positions, velocities, angular momenta,
    /// loads and springs are the same bits (`tests/sphere_flat_orientation.rs`) and only the
    /// orientations stay at their value when tracking was turned off (and are written back so). For runs
    /// whose outputs read no orientation (the sphere-bed benchmark): it saves the turn of every sphere in
    /// every step.
    pub fn set_track_orientation(&mut self, on: bool) {
        self.track_orientation = on;
    }

    /// Whether the drift turns the orientations (see [`SphereSim::set_track_orientation`]).
    pub fn tracks_orientation(&self) -> bool {
        self.track_orientation
    }

    /// How the threads of a team share a step's work ([`TeamSplit`]; shares outside 0..=1 are clamped,
    /// non-finite ones replaced by the default's). The bits are the same for any split; only the speed
    /// changes. Takes effect from the next step, which runs its passes one by one and makes the blocks
    /// anew.
    pub fn set_team_split(&mut self, split: TeamSplit) {
        self.split = split.sanitized();
        self.blocks.built_for = (u64::MAX, 0);
    }

    /// How the threads of a team share a step's work (see [`SphereSim::set_team_split`]).
    pub fn team_split(&self) -> TeamSplit {
        self.split
    }

    /// Whether the passes of a step run in their x86-64-v3 build (AVX2; see the module `isa`). On by
    /// default where the CPU has the features; `on = true` is refused (returns false) where it has not.
    /// The same bits either way (`tests/sphere_flat_paths.rs`); off is for that comparison and for
    /// measuring what the wider instructions give. Returns whether they are on.
    pub fn set_wide_instructions(&mut self, on: bool) -> bool {
        self.v3 = on && isa::v3();
        self.v3
    }

    /// Whether the per-sphere passes run on the pool (results are the same bits either way).
    fn parallel_bodies(&self) -> bool {
        rayon::current_num_threads() > 1 && self.kin.len() >= MIN_PARALLEL_BODIES
    }

    /// Number of spheres.
    pub fn len(&self) -> usize {
        self.kin.len()
    }

    /// Whether there are no spheres.
    pub fn is_empty(&self) -> bool {
        self.kin.is_empty()
    }

    /// Centre of sphere `i` (m).
    pub fn position(&self, i: usize) -> Point {
        self.kin[i].position
    }

    /// Velocity of sphere `i` (m/s).
    pub fn velocity(&self, i: usize) -> Vector {
        self.kin[i].velocity
    }

    /// Angular momentum of sphere `i` (kg·m²/s, world frame).
    pub fn angular_momentum(&self, i: usize) -> Vector {
        self.spin[i].angular_momentum
    }

    /// Orientation of sphere `i` (body to world).
    pub fn orientation(&self, i: usize) -> Rotation {
        self.spin[i].orientation
    }

    /// Contact force on each sphere from the last evaluation (N).
    pub fn forces(&self) -> &[Vector] {
        &self.force
    }

    /// Contact torque on each sphere from the last evaluation (N·m).
    pub fn torques(&self) -> &[Vector] {
        &self.torque
    }

    /// Contact force on each wall (N) from the last evaluation.
    pub fn wall_forces(&self) -> &[Vector] {
        &self.wall_forces
    }

    /// Σ of the elastic potentials of the contacts of the last evaluation (J), summed in pair order.
    pub fn elastic_potential(&self) -> Real {
        if !self.outs_valid {
            return self.start_potential;
        }
        // The law's potentials of each overlapping pair (normal k_n δ^(n+1)/(n+1), tangential ½ k_t |u|²
        // from the spring the evaluation left), in pair order: the general step's sum.
        let list = &self.list;
        let model = |a: u32, b: u32| {
            self.models[a as usize * self.n_materials + b as usize]
                .as_ref()
                .expect("an overlapping pair was evaluated with its model")
        };
        let potential = |model: &ContactModel, depth: Real, h: &crate::law::TangentialHistory| {
            model.normal.potential(depth) + 0.5 * h.stiffness * h.displacement.norm_squared()
        };
        let mut sum = 0.0;
        for (p, o) in self.out.iter().enumerate() {
            if list.in_contact[p] {
                let (a, b) = (list.a[p] as usize, list.b[p] as usize);
                let m = pair::scaled(
                    model(self.props[a].material, self.props[b].material),
                    list.root_radius[p],
                );
                sum += potential(&m, o.depth, &list.histories[p]);
            }
        }
        for (q, o) in self.wall_out.iter().enumerate() {
            if list.wall_in_contact[q] {
                let (body, wall) = (list.wall_body[q] as usize, list.wall_of[q] as usize);
                let m = model(self.planes[wall].material, self.props[body].material)
                    .for_contact_radii(None, Some(self.props[body].radius));
                sum += potential(&m, o.depth, &list.wall_histories[q]);
            }
        }
        sum
    }

    /// Simulated time (s).
    pub fn time(&self) -> Real {
        self.time
    }

    /// Completed steps.
    pub fn step_index(&self) -> u64 {
        self.step_index
    }

    /// The neighbour lists as they stand.
    pub fn neighbours(&self) -> &NeighbourList {
        &self.list
    }

    /// Listed body pairs (a, b), a < b, in key order.
    pub fn body_pairs(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.list.a.iter().copied().zip(self.list.b.iter().copied())
    }

    /// Listed body–wall pairs (body, wall), in key order.
    pub fn wall_pairs(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.list
            .wall_body
            .iter()
            .copied()
            .zip(self.list.wall_of.iter().copied())
    }

    /// Puts the state back into `world` (the world this simulation was made from, possibly restored
    /// since): bodies, walls, loads, ledger, time and step index, and a contact store holding every listed
    /// pair with its spring, its last forces and the geometry the general step would have stored for it
    /// at the current positions; the broad phase is reset so that the general step rebuilds its lists.
    pub fn write_back(&self, world: &mut World) {
        self.write_back_bodies(world);
        world.broad_phase = BroadPhase::new(world.broad_phase.skin());
        if !self.outs_valid {
            // Nothing evaluated here: the world's store is still the state.
            return;
        }
        world.contacts = self.contact_store();
    }

    /// Puts the bodies, walls, loads, ledger, time and step index back into `world`, and nothing else: its
    /// contact store and broad phase stay as they were (for an output that reads bodies and loads only;
    /// [`Self::write_back`] is the whole state).
    pub(crate) fn write_back_bodies(&self, world: &mut World) {
        for (i, body) in world.bodies.iter_mut().enumerate() {
            body.position = self.kin[i].position;
            body.velocity = self.kin[i].velocity;
            body.angular_momentum = self.spin[i].angular_momentum;
            body.orientation = self.spin[i].orientation;
        }
        world.walls.clone_from(&self.walls);
        world.ledger = self.ledger;
        world.time = self.time;
        world.step_index = self.step_index;
        let loads = &mut world.loads;
        loads.forces.clone_from(&self.force);
        loads.torques.clone_from(&self.torque);
        loads.wall_forces.clone_from(&self.wall_forces);
        loads.elastic_potential = self.elastic_potential();
        loads.damping_work = self.step_work.damping;
        loads.friction_dissipation = self.step_work.friction;
        loads.tangential_stiffness_work = self.step_work.stiffness;
        loads.external_power = self.external_power;
        loads.current = true;
    }

    /// The contact store the general step would hold: every listed pair with its spring, its last forces
    /// and its geometry at the current positions.
    fn contact_store(&self) -> ContactStore {
        let list = &self.list;
        let keys: Vec<ContactKey> = self
            .body_pairs()
            .map(|(a, b)| ContactKey::Body { a, b })
            .chain(
                list.wall_body
                    .iter()
                    .zip(&list.wall_of)
                    .map(|(&body, &wall)| ContactKey::Wall { body, wall }),
            )
            .collect();
        let mut store = ContactStore::default();
        store.sync(&keys, self.step_index.saturating_sub(1));
        let tol = &self.params.tolerances;
        let bounding = self.params.skips.bounding_spheres;
        let mut counters = QueryCounters::default();
        let n_body = list.a.len();
        for (k, state) in store.states_mut().iter_mut().enumerate() {
            let (history, since, in_contact, out) = if k < n_body {
                (
                    list.histories[k],
                    list.since[k],
                    list.in_contact[k],
                    &self.out[k],
                )
            } else {
                let q = k - n_body;
                (
                    list.wall_histories[q],
                    list.wall_since[q],
                    list.wall_in_contact[q],
                    &self.wall_out[q],
                )
            };
            let geometry = match keys[k] {
                ContactKey::Body { a, b } => {
                    let (a, b) = (a as usize, b as usize);
                    let (xa, xb) = (&self.kin[a].position, &self.kin[b].position);
                    let (ra, rb) = (self.props[a].radius, self.props[b].radius);
                    sphere_pair_geometry(xa, ra, xb, rb, bounding, tol, &mut counters)
                }
                ContactKey::Wall { body, wall } => {
                    let (x, r) = (
                        &self.kin[body as usize].position,
                        self.props[body as usize].radius,
                    );
                    let w = &self.walls[wall as usize];
                    wall_sphere_geometry(w, x, r, bounding, tol, &mut counters)
                }
            };
            let (force_on_b, damping_force) = if in_contact {
                (out.force_on_b, out.damping_force)
            } else {
                (Vector::zeros(), Vector::zeros())
            };
            *state = ContactState {
                history,
                since_step: since,
                geometry,
                force_on_b,
                damping_force,
                ..ContactState::new(since)
            };
        }
        store
    }
}

/// Why [`SphereSim::from_world`] failed: the world does not fit the path, or its initial evaluation
/// failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepFlatError {
    /// The world does not fit the flat sphere path.
    #[error(transparent)]
    NotSphereOnly(#[from] NotSphereOnly),
    /// The initial force evaluation failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

/// From this many spheres on, the per-sphere passes run on the pool when it has several threads (one
/// pass over 1024 spheres is well above the cost of a fork/join on a busy pool: `docs/tuning.md`).
pub const MIN_PARALLEL_BODIES: usize = 1024;

/// From this many listed pairs on, the pair loop runs on the pool when it has several threads.
pub const MIN_PARALLEL_PAIRS: usize = 2048;

/// The sub-rotation of the splitting scheme, if `params` and `world` allow the flat layout (the skips of
/// isotropic and still rotation, no global damping, no sleeping).
fn flat_sub_rotation(world: &World, params: &StepParams) -> Result<SubRotation, StepFlatError> {
    let need = |ok: bool, what: &'static str| {
        if ok {
            Ok(())
        } else {
            Err(NotSphereOnly::Params { what })
        }
    };
    let RotationScheme::Splitting { sub_rotation } = params.rotation else {
        return Err(NotSphereOnly::Params {
            what: "the splitting rotation scheme",
        }
        .into());
    };
    need(
        params.skips.isotropic_rotation && params.skips.still_rotation,
        "the isotropic_rotation and still_rotation skips",
    )?;
    need(
        params.damping == ViscousDamping::None,
        "no global viscous damping",
    )?;
    need(
        !params.sleeping.enabled && world.sleep.sleeping == 0,
        "sleeping off",
    )?;
    Ok(sub_rotation)
}

/// The flat layout's kinematics, spins and constants of every body, if every body is a free sphere with
/// an isotropic inertia.
fn flat_bodies(world: &World) -> Result<FlatBodies, StepFlatError> {
    let n = world.bodies.len();
    let (mut kin, mut spin, mut props) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for (i, body) in world.bodies.iter().enumerate() {
        let name = || world.names[i].clone();
        let Shape::Sphere(sphere) = world.shape(i) else {
            return Err(NotSphereOnly::NotASphere {
                body: i,
                name: name(),
            }
            .into());
        };
        if !matches!(body.motion, Motion::Dynamic) {
            return Err(NotSphereOnly::NotDynamic {
                body: i,
                name: name(),
            }
            .into());
        }
        if !is_isotropic(&body.inertia.0) {
            return Err(NotSphereOnly::Anisotropic {
                body: i,
                name: name(),
            }
            .into());
        }
        let moment = body.inertia.0.x;
        kin.push(Kinematic {
            position: body.position,
            velocity: body.velocity,
            omega: body.angular_momentum / moment,
        });
        spin.push(Spin {
            angular_momentum: body.angular_momentum,
            orientation: body.orientation,
        });
        props.push(Props {
            radius: sphere.radius(),
            mass: body.mass,
            moment,
            material: world.material_of[i],
        });
    }
    Ok(FlatBodies { kin, spin, props })
}

/// Every body in the flat layout: its kinematics, its spin and its constants.
struct FlatBodies {
    kin: Vec<Kinematic>,
    spin: Vec<Spin>,
    props: Vec<Props>,
}
