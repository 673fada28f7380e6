//! Sleeping: bodies at rest are frozen, their mutual contacts are not re-evaluated, and a disturbance wakes
//! only the bodies whose load it changes (a wake front that travels with it).
//!
//! # When a body is calm
//! A dynamic, awake body is *calm* at the end of a step when, with |g| the gravity, d its bounding diameter
//! and r = d/2 (all thresholds scale with the particle and the gravity, so one setting serves rocks of any
//! size):
//! - its speed |v| and the rim speed |ω| r of its spin are below `rest_speed · √(|g| d)` (default 1e-3:
//!   about 1 mm/s for a 0.1 m rock; in one contact time such a body moves ~1e-6 of its size);
//! - the net force |F_contact + m g| is below `rest_force · m |g|` and the contact torque |τ| below
//!   `rest_force · m |g| r` (default 1e-2: what is left would accelerate the body by 1 % of g);
//! - it touches no moving wall and no prescribed body.
//!
//! A body calm for `steps` consecutive steps (default 200, five contact times at Δt = t_c/40: long enough
//! for a rebound to show) falls asleep at the end of the step (stage 8b): its velocity and angular momentum
//! are set to zero, the kinetic energy removed is booked in the ledger (`EnergyLedger::removed_by_sleeping`,
//! so the balance still closes), each of its contacts that becomes frozen (below) keeps the force it has at
//! zero relative velocity (elastic normal force and tangential spring: the damping of the last motion is
//! dropped, since a re-evaluation at rest would not give it), and its *rest load* — the net force F + m g
//! and the torque τ of these forces — is kept. Each body falls asleep on its own: a bed does not have to come
//! to rest as a whole.
//!
//! Without gravity nothing is ever calm (every threshold is zero) and sleeping does nothing.
//!
//! # Waking: local, by load
//! A sleeping body wakes (stage 6b, right after the force evaluation and before the second half kick, so
//! that it receives the impulse of the step in which it was disturbed) when
//! - its net load departs from its rest load by more than the wake limit L: |F + m g − F_rest| above L, or
//!   |τ − τ_rest| above L r, with L = max(`rest_force` · m |g|, `wake_contact_fraction` · Σ|f|) and Σ|f| the
//!   sum of its contact force magnitudes at rest; or
//! - it touches a moving wall or a prescribed body.
//!
//! The load of a sleeping body is the sum of its frozen contact forces (below) and of the forces of its
//! contacts with awake bodies, which are evaluated normally. An awake body thus leans on its sleeping
//! neighbours as on fixed supports that carry their frozen forces, and each of them wakes as soon as the
//! awake body pushes on it (or lets go of it) by more than 1 % of its weight: a projectile's first step of
//! overlap with a rock exceeds that by orders of magnitude, and a rock pushed by a woken neighbour wakes when
//! the neighbour has moved ~1e-7 of its size (at rockfill stiffness). The woken region grows with the
//! disturbance, body by body, instead of waking every body connected to it by contacts: in a dense bed,
//! where every rock touches the next, the connected component is the whole bed. A touch by an awake body is
//! not a reason to wake by itself: its force is (a new contact's force wakes the body in the step in which it
//! exceeds the threshold, a fast impact in its first step).
//!
//! `wake_contact_fraction` (default 0: off) is for stressed packings: in a compacted rockfill every contact
//! carries several rock weights, and 1 % of the weight is a fraction of a per mille of the contact forces.
//! The explicit step hands any disturbance on by one contact per step (through the dashpots at once, through
//! the springs after a few steps), so at that sensitivity a disturbance anywhere wakes the whole bed within
//! tens of steps — far ahead of the physical wave (`docs/tuning.md`). A limit of a fraction of the contact forces
//! keeps the region woken to where the forces really change.
//!
//! [`put_to_sleep`] puts bodies to sleep at once (a bed loaded from a checkpoint of a packing at rest), in
//! the same way. Their contacts must have been evaluated (a checkpointed bed): a body put to sleep in a world
//! without contact state gets its weight as rest load, and its first evaluated contacts wake it.
//!
//! # What a sleeping body and its contacts do
//! A sleeping body is not integrated. A contact between two sleeping bodies, or between a sleeping body and a
//! fixed body or a fixed wall, is *frozen* (`is_frozen`): neither queried nor evaluated. It keeps the
//! geometry and the force of its last evaluation, and contributes them to the loads (force, torques about
//! the unmoved centres, elastic energy at the kept overlap; no damping or friction work since nothing
//! moves). Keeping the last forces, rather than dropping them, is what keeps a resting pile in equilibrium
//! when it wakes: at that moment every frozen contact carries the force it would have if re-evaluated at
//! zero relative velocity (the geometry has not changed), so the woken bodies start from the equilibrium they
//! fell asleep in, and a floor under a sleeping pile still reports the pile's weight.
//!
//! # Cost
//! The frozen contributions do not change while the set of sleeping bodies and the contact store's pairs do
//! not: `FrozenLoads` sums them once, in candidate order, and the step adds the sums to the loads instead
//! of touching every frozen pair at every step. A frozen candidate then costs the broad phase's pair, one
//! flag test in the narrow-phase pass and one in the accumulation. The sums are rebuilt when a body falls
//! asleep or wakes, or when the store's pairs change; they are a function of the state only (the same on
//! any thread count and after a restart from a checkpoint).
//!
//! Every decision is taken serially, in body and key order, so runs are bit-identical for any number of
//! threads (`tests/world_sleeping.rs`).
//!
//! Sleeping is off by default: it changes the dynamics within the thresholds above, so a run that must
//! reproduce exact dynamics (the validation cases) does not use it.

use crate::contact::{ContactGeometry, ContactKind};
use crate::dynamics::Motion;
use crate::law::ContactKinematics;
use crate::math::{Point, Real, Vector};
use crate::shape::Shape;

use super::contact_store::{ContactKey, ContactState};
use super::world::World;

pub use super::sleep_state::{
    SleepCounts, SleepParams, SleepState, DEFAULT_REST_FORCE, DEFAULT_REST_SPEED,
    DEFAULT_SLEEP_STEPS,
};

/// Whether the contact `key` is frozen: both sides asleep, or one side asleep and the other fixed (a fixed
/// body or a wall that does not move).
#[inline]
pub(crate) fn is_frozen(world: &World, key: ContactKey) -> bool {
    let sleep = &world.sleep;
    if sleep.sleeping == 0 {
        return false;
    }
    let still = |i: usize| sleep.asleep[i] || matches!(world.bodies[i].motion, Motion::Fixed);
    match key {
        ContactKey::Body { a, b } => {
            let (a, b) = (a as usize, b as usize);
            (sleep.asleep[a] || sleep.asleep[b]) && still(a) && still(b)
        }
        ContactKey::Wall { body, wall } => {
            sleep.asleep[body as usize] && world.walls[wall as usize].velocity == Vector::zeros()
        }
    }
}

/// Whether the stored contact `key` is frozen now: [`is_frozen`], and evaluated at least once before (a pair
/// that entered the candidate list at this step has no kept geometry yet: it is evaluated once, then frozen).
#[inline]
pub(crate) fn is_frozen_entry(world: &World, key: ContactKey, state: &ContactState) -> bool {
    state.since_step < world.step_index && is_frozen(world, key)
}

/// Puts the dynamic bodies of `bodies` to sleep now (skipping those already asleep), with the loads of the
/// last evaluation (`world.loads`, also when they are stale: a bed whose walls were just removed rested
/// against them) as their rest loads, or zero for a body the loads do not cover. Their kinetic energy is
/// booked as removed by sleeping. Returns how many fell asleep.
pub fn put_to_sleep(
    params: &SleepParams,
    world: &mut World,
    bodies: impl IntoIterator<Item = usize>,
) -> usize {
    world.sleep.resize(world.bodies.len());
    let mut count = 0;
    let mut removed = 0.0;
    let mut fell = vec![false; world.bodies.len()];
    for i in bodies {
        if i >= world.bodies.len() || !world.bodies[i].is_dynamic() || world.sleep.asleep[i] {
            continue;
        }
        let body = &mut world.bodies[i];
        removed += body.translational_kinetic_energy() + body.rotational_kinetic_energy();
        body.velocity = Vector::zeros();
        body.angular_momentum = Vector::zeros();
        let sleep = &mut world.sleep;
        sleep.asleep[i] = true;
        sleep.calm_steps[i] = 0;
        sleep.sleeping += 1;
        sleep.changes += 1;
        fell[i] = true;
        count += 1;
    }
    world.ledger.removed_by_sleeping += removed;
    if count > 0 {
        freeze(params, world, &fell);
    }
    count
}

/// The bodies flagged in `fell` have just fallen asleep: every contact of theirs that is now frozen keeps
/// the force it has at zero relative velocity (its elastic normal force and tangential spring, capped by
/// friction, without the damping of the motion it had — the force a re-evaluation at rest gives, so that
/// waking does not change it), and each of them gets as rest load the sum over its contacts of these forces
/// (and of the forces of its contacts with awake bodies) plus its weight. Serial, in key order.
fn freeze(params: &SleepParams, world: &mut World, fell: &[bool]) {
    let n_walls = world.walls.len();
    let touches = |key: ContactKey| match key {
        ContactKey::Body { a, b } => fell[a as usize] || fell[b as usize],
        ContactKey::Wall { body, wall } => fell[body as usize] && (wall as usize) < n_walls,
    };
    for k in 0..world.contacts.len() {
        let key = world.contacts.keys()[k];
        if !touches(key) || !world.contacts.states()[k].is_active() || !is_frozen(world, key) {
            continue;
        }
        let force = static_force(world, k);
        let state = &mut world.contacts.states_mut()[k];
        state.force_on_b = force;
        // What acts while frozen has no damping part (the energy ledger books the last damping force).
        state.damping_force = Vector::zeros();
    }
    let sleep = &mut world.sleep;
    for (i, body) in world.bodies.iter().enumerate() {
        if fell[i] {
            sleep.rest_force[i] = body.mass * world.gravity;
            sleep.rest_torque[i] = Vector::zeros();
            // Σ|f| first, the limit below.
            sleep.wake_limit[i] = 0.0;
        }
    }
    for (key, state) in world.contacts.keys().iter().zip(world.contacts.states()) {
        if !touches(*key) || !state.is_active() {
            continue;
        }
        let (force, point) = (state.force_on_b, state.geometry.point);
        let (a, b) = match *key {
            ContactKey::Body { a, b } => (Some(a as usize), b as usize),
            ContactKey::Wall { body, .. } => (None, body as usize),
        };
        if let Some(a) = a.filter(|&a| fell[a]) {
            sleep.rest_force[a] -= force;
            sleep.rest_torque[a] += (point - world.bodies[a].position).cross(&(-force));
            sleep.wake_limit[a] += force.norm();
        }
        if fell[b] {
            sleep.rest_force[b] += force;
            sleep.rest_torque[b] += (point - world.bodies[b].position).cross(&force);
            sleep.wake_limit[b] += force.norm();
        }
    }
    let g = world.gravity.norm();
    for (i, body) in world.bodies.iter().enumerate() {
        if fell[i] {
            let contacts = sleep.wake_limit[i];
            sleep.wake_limit[i] =
                (params.rest_force * body.mass * g).max(params.wake_contact_fraction * contacts);
        }
    }
}

/// Side A of a stored contact, as its law needs it: (centre or, for a wall, the contact point on it,
/// material, shape if a body, index of body B).
fn side_a<'w>(
    world: &'w World,
    key: ContactKey,
    g: &ContactGeometry,
) -> (Point, u32, Option<&'w Shape>, usize) {
    match key {
        ContactKey::Body { a, b } => {
            let a = a as usize;
            (
                world.bodies[a].position,
                world.material_of[a],
                Some(world.shape(a)),
                b as usize,
            )
        }
        ContactKey::Wall { body, wall } => (
            g.point_a,
            world.walls[wall as usize].material,
            None,
            body as usize,
        ),
    }
}

/// The force on B of the stored contact `k`, evaluated by its law on the kept geometry at zero relative
/// velocity and with no tangential increment (the kept tangential spring, capped by friction).
fn static_force(world: &World, k: usize) -> Vector {
    let key = world.contacts.keys()[k];
    let state = &world.contacts.states()[k];
    let g = &state.geometry;
    let (center_a, mat_a, shape_a, b) = side_a(world, key, g);
    let Some(model) = world.materials.model(mat_a, world.material_of[b]) else {
        return state.force_on_b;
    };
    let model = model.for_shapes(shape_a, world.shape(b));
    let kinematics = ContactKinematics {
        relative_velocity: Vector::zeros(),
        effective_mass: world.bodies[b].mass,
        center_a,
        center_b: world.bodies[b].position,
        dt: 0.0,
    };
    let mut history = state.history;
    model.evaluate(g, &kinematics, &mut history).force_on_b
}

/// Stage 6b, between the force evaluation and the second half kick: wakes every sleeping body whose load
/// departs from its rest load by more than the thresholds, or that touches a moving wall or a prescribed
/// body (see the module docs). Serial, in body then key order.
pub(crate) fn wake_disturbed(world: &mut World) -> u64 {
    if world.sleep.sleeping == 0 {
        return 0;
    }
    let mut woken = 0;
    for i in 0..world.bodies.len() {
        if !world.sleep.asleep[i] {
            continue;
        }
        let body = &world.bodies[i];
        let sleep = &world.sleep;
        let force = world.loads.forces[i] + body.mass * world.gravity - sleep.rest_force[i];
        let torque = world.loads.torques[i] - sleep.rest_torque[i];
        let limit = sleep.wake_limit[i];
        if force.norm_squared() > limit * limit
            || torque.norm_squared() > (limit * world.radii[i]).powi(2)
        {
            world.sleep.wake(i);
            woken += 1;
        }
    }
    if world.sleep.sleeping > 0 && has_movers(world) {
        for k in 0..world.contacts.len() {
            let (key, state) = (world.contacts.keys()[k], &world.contacts.states()[k]);
            if !state.is_active() {
                continue;
            }
            for (i, moving) in touched_by_movers(world, key).into_iter().flatten() {
                if moving && world.sleep.asleep[i] {
                    world.sleep.wake(i);
                    woken += 1;
                }
            }
        }
    }
    woken
}

/// Whether anything moves without responding to forces: a wall with a velocity or a prescribed body.
fn has_movers(world: &World) -> bool {
    world.walls.iter().any(|w| w.velocity != Vector::zeros())
        || world
            .bodies
            .iter()
            .any(|b| matches!(b.motion, Motion::Prescribed { .. }))
}

/// The dynamic bodies of the pair `key`, each with whether its partner is a moving wall or a prescribed
/// body.
fn touched_by_movers(world: &World, key: ContactKey) -> [Option<(usize, bool)>; 2] {
    match key {
        ContactKey::Body { a, b } => {
            let (a, b) = (a as usize, b as usize);
            let prescribed = |i: usize| matches!(world.bodies[i].motion, Motion::Prescribed { .. });
            [
                world.bodies[a].is_dynamic().then(|| (a, prescribed(b))),
                world.bodies[b].is_dynamic().then(|| (b, prescribed(a))),
            ]
        }
        ContactKey::Wall { body, wall } => [
            Some((
                body as usize,
                world.walls[wall as usize].velocity != Vector::zeros(),
            )),
            None,
        ],
    }
}

/// Stage 8b, the end-of-step update (see the module docs): calm counters of the awake bodies, and the
/// bodies calm for long enough fall asleep, each on its own. Serial, in body order.
pub(crate) fn update(params: &SleepParams, world: &mut World) -> SleepCounts {
    let n = world.bodies.len();
    let g = world.gravity.norm();
    let mut counts = SleepCounts::default();
    // Calm counters of the awake dynamic bodies.
    for i in 0..n {
        let body = &world.bodies[i];
        if !body.is_dynamic() || world.sleep.asleep[i] {
            continue;
        }
        let r = world.radii[i];
        let rest_speed = params.rest_speed * (g * 2.0 * r).sqrt();
        let weight = body.mass * g;
        let calm = body.velocity.norm() < rest_speed
            && body.angular_velocity().norm() * r < rest_speed
            && (world.loads.forces[i] + body.mass * world.gravity).norm()
                < params.rest_force * weight
            && world.loads.torques[i].norm() < params.rest_force * weight * r;
        let c = &mut world.sleep.calm_steps[i];
        *c = if calm { c.saturating_add(1) } else { 0 };
    }
    // Moving walls and prescribed bodies make their partners restless.
    if has_movers(world) {
        for k in 0..world.contacts.len() {
            if !world.contacts.states()[k].is_active() {
                continue;
            }
            let key = world.contacts.keys()[k];
            for (i, moving) in touched_by_movers(world, key).into_iter().flatten() {
                if !moving {
                    continue;
                }
                world.sleep.calm_steps[i] = 0;
                if world.sleep.asleep[i] {
                    world.sleep.wake(i);
                    counts.woken += 1;
                }
            }
        }
    }
    // Falling asleep.
    let mut removed = 0.0;
    let mut fell: Vec<bool> = Vec::new();
    for i in 0..n {
        let sleep = &mut world.sleep;
        if sleep.asleep[i] || sleep.calm_steps[i] < params.steps || !world.bodies[i].is_dynamic() {
            continue;
        }
        let body = &mut world.bodies[i];
        removed += body.translational_kinetic_energy() + body.rotational_kinetic_energy();
        body.velocity = Vector::zeros();
        body.angular_momentum = Vector::zeros();
        sleep.asleep[i] = true;
        sleep.sleeping += 1;
        sleep.changes += 1;
        counts.fell_asleep += 1;
        fell.resize(n, false);
        fell[i] = true;
    }
    world.ledger.removed_by_sleeping += removed;
    if counts.fell_asleep > 0 {
        freeze(params, world, &fell);
    }
    counts
}

/// One frozen contact's contribution (see the module docs): the kept force, the torques about the unmoved
/// centres and the elastic energy at the kept overlap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FrozenContact {
    pub key: ContactKey,
    pub force_on_b: Vector,
    pub torque_on_a: Vector,
    pub torque_on_b: Vector,
    pub potential: Real,
    /// Overlap δ_M (m) and δ_M over the smaller particle's length scale.
    pub depth: Real,
    pub overlap_ratio: Real,
}

/// The contribution of the frozen contact `k` of the store, or `None` if it does not overlap.
fn frozen_contact(world: &World, k: usize) -> Option<FrozenContact> {
    let key = world.contacts.keys()[k];
    let state = &world.contacts.states()[k];
    let g = &state.geometry;
    if g.kind != ContactKind::Overlap {
        return None;
    }
    let (center_a, mat_a, shape_a, b) = side_a(world, key, g);
    // A frozen pair was evaluated before, so its law exists; a missing one contributes no energy.
    let potential = world
        .materials
        .model(mat_a, world.material_of[b])
        .map_or(0.0, |model| {
            let model = model.for_shapes(shape_a, world.shape(b));
            let (k_t, _) = model.tangential.stiffness_and_friction(g.depth);
            model.normal.potential(g.depth) + 0.5 * k_t * state.history.displacement.norm_squared()
        });
    let scale = match key {
        ContactKey::Body { a, .. } => world.length_scale(a as usize).min(world.length_scale(b)),
        ContactKey::Wall { .. } => world.length_scale(b),
    };
    let force = state.force_on_b;
    Some(FrozenContact {
        key,
        force_on_b: force,
        torque_on_a: (g.point - center_a).cross(&(-force)),
        torque_on_b: (g.point - world.bodies[b].position).cross(&force),
        potential,
        depth: g.depth,
        overlap_ratio: g.depth / scale,
    })
}

/// The summed contributions of the frozen contacts (see "Cost" in the module docs), kept in the step's
/// scratch and rebuilt when they may have changed.
#[derive(Clone, Debug, Default)]
pub(crate) struct FrozenLoads {
    /// The state they were built for: the sleeping set's change count, the step, the body and wall counts.
    built_for: Option<(u64, u64, usize, usize)>,
    /// Whether a pair that will be frozen was left out because it had not been evaluated yet.
    pending: bool,
    /// Per body with a frozen contact, in body order: (body, force, torque).
    bodies: Vec<(u32, Vector, Vector)>,
    /// Per wall: the force of its frozen contacts on it.
    pub wall_forces: Vec<Vector>,
    pub potential: Real,
    /// Frozen overlapping contacts, the largest overlap ratio among them, and those above the warning
    /// fraction the sums were built with.
    pub contacts: usize,
    pub max_overlap_ratio: Real,
    pub deep: Vec<FrozenContact>,
    /// Scratch of the rebuild: per body, its sums and whether it has any.
    sums: Vec<(Vector, Vector, bool)>,
}

impl FrozenLoads {
    /// Rebuilds the sums unless they were built for this state (the same sleeping set, the previous or this
    /// step, unchanged store pairs: `store_changed` says the store's last sync created or dropped entries).
    /// Returns whether it rebuilt.
    pub(crate) fn ensure(
        &mut self,
        world: &World,
        store_changed: bool,
        warning_fraction: Real,
    ) -> bool {
        let state = (
            world.sleep.changes,
            world.step_index,
            world.bodies.len(),
            world.walls.len(),
        );
        let current = self
            .built_for
            .is_some_and(|(changes, step, bodies, walls)| {
                changes == state.0
                    && (step == state.1 || (step + 1 == state.1 && !self.pending))
                    && (bodies, walls) == (state.2, state.3)
                    && !store_changed
            });
        self.built_for = Some(state);
        if current {
            return false;
        }
        self.clear(world.walls.len());
        if world.sleep.sleeping == 0 {
            return true;
        }
        self.sums.clear();
        self.sums.resize(
            world.bodies.len(),
            (Vector::zeros(), Vector::zeros(), false),
        );
        for (k, (&key, entry)) in world
            .contacts
            .keys()
            .iter()
            .zip(world.contacts.states())
            .enumerate()
        {
            if !is_frozen(world, key) {
                continue;
            }
            if entry.since_step >= world.step_index {
                self.pending = true;
                continue;
            }
            if let Some(c) = frozen_contact(world, k) {
                self.add(c, warning_fraction);
            }
        }
        for (i, &(force, torque, any)) in self.sums.iter().enumerate() {
            if any {
                self.bodies.push((i as u32, force, torque));
            }
        }
        true
    }

    /// Empties the sums, for a world of `walls` walls.
    fn clear(&mut self, walls: usize) {
        self.pending = false;
        self.bodies.clear();
        self.wall_forces.clear();
        self.wall_forces.resize(walls, Vector::zeros());
        self.potential = 0.0;
        self.contacts = 0;
        self.max_overlap_ratio = 0.0;
        self.deep.clear();
    }

    /// Adds one frozen contact to its bodies' (and wall's) sums and to the totals.
    fn add(&mut self, c: FrozenContact, warning_fraction: Real) {
        match c.key {
            ContactKey::Body { a, b } => {
                let sa = &mut self.sums[a as usize];
                sa.0 -= c.force_on_b;
                sa.1 += c.torque_on_a;
                sa.2 = true;
                let sb = &mut self.sums[b as usize];
                sb.0 += c.force_on_b;
                sb.1 += c.torque_on_b;
                sb.2 = true;
            }
            ContactKey::Wall { body, wall } => {
                self.wall_forces[wall as usize] -= c.force_on_b;
                let s = &mut self.sums[body as usize];
                s.0 += c.force_on_b;
                s.1 += c.torque_on_b;
                s.2 = true;
            }
        }
        self.potential += c.potential;
        self.contacts += 1;
        self.max_overlap_ratio = self.max_overlap_ratio.max(c.overlap_ratio);
        if c.overlap_ratio > warning_fraction {
            self.deep.push(c);
        }
    }

    /// Adds the per-body sums to `forces` and `torques`.
    pub(crate) fn add_to(&self, forces: &mut [Vector], torques: &mut [Vector]) {
        for &(i, force, torque) in &self.bodies {
            forces[i as usize] += force;
            torques[i as usize] += torque;
        }
    }
}
