//! Sleeping: bodies at rest are frozen, and the contacts among frozen bodies are not re-evaluated.
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
//! Without gravity nothing is ever calm (every threshold is zero) and sleeping does nothing.
//!
//! # Islands
//! The *islands* are the connected components of the graph of overlapping body pairs among dynamic bodies
//! (fixed bodies and walls do not connect: a floor does not make a whole bed one island). An island falls
//! asleep as a whole, when every member is asleep or has been calm for `steps` consecutive steps (default
//! 200, five contact times at Δt = t_c/40: long enough for any rebound inside the island to show). An island
//! that contains an awake member not calm for that long is awake as a whole: an awake body touching a
//! sleeping island, or a moving wall or prescribed body touching one of its members, wakes every member of
//! it. Waking by touch is checked right after the force evaluation, before the second half kick (stage 6b
//! of the step), so a woken body receives the impulse of the step in which it was hit; falling asleep is
//! decided at the end of the step (stage 8b). The graph and the decisions are computed serially, in body and key order, so they do not depend on
//! the number of threads.
//!
//! # What a sleeping body and its contacts do
//! A body falling asleep has its velocity and angular momentum set to zero; the kinetic energy removed is
//! accounted in the ledger (`EnergyLedger::removed_by_sleeping`), so the energy balance still closes. A
//! sleeping body is not integrated. A contact between two sleeping bodies, or between a sleeping body and a
//! fixed body or a fixed wall, is *frozen*: neither queried nor evaluated. It keeps the geometry and the
//! force of its last evaluation, and contributes them to the loads (force, torques about the unmoved
//! centres, elastic energy at the kept overlap; no damping or friction work since nothing moves). Keeping
//! the last forces, rather than dropping them, is what keeps a resting pile in equilibrium when it wakes:
//! at that moment every frozen contact carries the force it would have if re-evaluated at zero relative
//! velocity (the geometry has not changed), so the woken bodies start from the equilibrium they fell asleep
//! in, and a floor under a sleeping pile still reports the pile's weight. Contacts between a sleeping body
//! and an awake one are evaluated normally (they exist only in the step at which they wake the island).
//!
//! Sleeping is off by default: it changes the dynamics within the thresholds above, so a run that must
//! reproduce exact dynamics (the validation cases) does not use it.

use crate::math::Real;

use super::contact_store::ContactKey;
use super::world::World;

/// The settings of sleeping (see the module docs for what each threshold means and why its default).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SleepParams {
    pub enabled: bool,
    /// Rest speed as a fraction of √(|g| d).
    pub rest_speed: Real,
    /// Rest force as a fraction of the weight m |g| (and rest torque of m |g| r).
    pub rest_force: Real,
    /// Consecutive calm steps before a body may fall asleep.
    pub steps: u32,
}

/// Default [`SleepParams::rest_speed`] (see the module docs).
pub const DEFAULT_REST_SPEED: Real = 1e-3;
/// Default [`SleepParams::rest_force`] (see the module docs).
pub const DEFAULT_REST_FORCE: Real = 1e-2;
/// Default [`SleepParams::steps`] (see the module docs).
pub const DEFAULT_SLEEP_STEPS: u32 = 200;

impl Default for SleepParams {
    /// Off, with the default thresholds.
    fn default() -> Self {
        Self {
            enabled: false,
            rest_speed: DEFAULT_REST_SPEED,
            rest_force: DEFAULT_REST_FORCE,
            steps: DEFAULT_SLEEP_STEPS,
        }
    }
}

impl SleepParams {
    /// On, with the default thresholds.
    pub fn on() -> Self {
        Self {
            enabled: true,
            ..Self::default()
        }
    }
}

/// Per-body sleeping state, kept in the world.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SleepState {
    /// Whether each body is asleep.
    pub asleep: Vec<bool>,
    /// Consecutive calm steps of each awake body.
    pub calm_steps: Vec<u32>,
    /// Number of sleeping bodies.
    pub sleeping: usize,
}

impl SleepState {
    /// Makes the state cover `n` bodies (new bodies are awake).
    pub(crate) fn resize(&mut self, n: usize) {
        self.asleep.resize(n, false);
        self.calm_steps.resize(n, 0);
    }

    pub fn is_asleep(&self, i: usize) -> bool {
        self.asleep.get(i).copied().unwrap_or(false)
    }
}

/// What one sleeping update did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SleepCounts {
    pub fell_asleep: u64,
    pub woken: u64,
}

/// Whether the contact `key` is frozen: both sides asleep, or one side asleep and the other fixed (a fixed
/// body or a wall that does not move).
pub(crate) fn is_frozen(world: &World, key: ContactKey) -> bool {
    let sleep = &world.sleep;
    if sleep.sleeping == 0 {
        return false;
    }
    let still = |i: usize| {
        sleep.asleep[i] || matches!(world.bodies[i].motion, crate::dynamics::Motion::Fixed)
    };
    match key {
        ContactKey::Body { a, b } => {
            let (a, b) = (a as usize, b as usize);
            (sleep.asleep[a] || sleep.asleep[b]) && still(a) && still(b)
        }
        ContactKey::Wall { body, wall } => {
            sleep.asleep[body as usize]
                && world.walls[wall as usize].velocity == crate::math::Vector::zeros()
        }
    }
}

/// Union–find with path halving, deterministic.
fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let grand = parent[parent[i as usize] as usize];
        parent[i as usize] = grand;
        i = grand;
    }
    i
}

/// Islands over the overlapping pairs of dynamic bodies (union–find into `parent`).
fn build_islands(world: &World, parent: &mut Vec<u32>) {
    parent.clear();
    parent.extend(0..world.bodies.len() as u32);
    for (key, state) in world.contacts.keys().iter().zip(world.contacts.states()) {
        if let ContactKey::Body { a, b } = *key {
            if state.is_active()
                && world.bodies[a as usize].is_dynamic()
                && world.bodies[b as usize].is_dynamic()
            {
                let (ra, rb) = (find(parent, a), find(parent, b));
                if ra != rb {
                    parent[ra.max(rb) as usize] = ra.min(rb);
                }
            }
        }
    }
}

/// Stage 6b, between the force evaluation and the second half kick: wakes every island in which a
/// sleeping body overlaps an awake dynamic body, a prescribed body or a moving wall, so that the woken
/// bodies receive this step's second half kick (a body woken only at the end of the step would miss half
/// an impulse). `disturbed` is scratch.
pub(crate) fn wake_touched(
    world: &mut World,
    parent: &mut Vec<u32>,
    disturbed: &mut Vec<bool>,
) -> u64 {
    if world.sleep.sleeping == 0 {
        return 0;
    }
    let n = world.bodies.len();
    build_islands(world, parent);
    disturbed.clear();
    disturbed.resize(n, false);
    let sleep = &world.sleep;
    let awake_mover = |i: usize| {
        let body = &world.bodies[i];
        match body.motion {
            crate::dynamics::Motion::Dynamic => !sleep.asleep[i],
            crate::dynamics::Motion::Prescribed { .. } => true,
            crate::dynamics::Motion::Fixed => false,
        }
    };
    for (key, state) in world.contacts.keys().iter().zip(world.contacts.states()) {
        if !state.is_active() {
            continue;
        }
        match *key {
            ContactKey::Body { a, b } => {
                let (a, b) = (a as usize, b as usize);
                for (this, other) in [(a, b), (b, a)] {
                    if sleep.asleep[this] && awake_mover(other) {
                        let root = find(parent, this as u32) as usize;
                        disturbed[root] = true;
                    }
                }
            }
            ContactKey::Wall { body, wall } => {
                let body = body as usize;
                if sleep.asleep[body]
                    && world.walls[wall as usize].velocity != crate::math::Vector::zeros()
                {
                    let root = find(parent, body as u32) as usize;
                    disturbed[root] = true;
                }
            }
        }
    }
    let mut woken = 0;
    for i in 0..n {
        if world.sleep.asleep[i] && disturbed[find(parent, i as u32) as usize] {
            world.sleep.asleep[i] = false;
            world.sleep.calm_steps[i] = 0;
            world.sleep.sleeping -= 1;
            woken += 1;
        }
    }
    woken
}

/// A body touched by something that moves: not calm, and awake.
fn make_restless(sleep: &mut SleepState, i: usize, counts: &mut SleepCounts) {
    sleep.calm_steps[i] = 0;
    if sleep.asleep[i] {
        sleep.asleep[i] = false;
        sleep.sleeping -= 1;
        counts.woken += 1;
    }
}

/// Stage 8b, the end-of-step update (see the module docs): calm counters, islands, falling asleep and
/// waking.
/// `parent` and `ready` are scratch buffers.
pub(crate) fn update(
    params: &SleepParams,
    world: &mut World,
    parent: &mut Vec<u32>,
    ready: &mut Vec<bool>,
) -> SleepCounts {
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
    for (key, state) in world.contacts.keys().iter().zip(world.contacts.states()) {
        if !state.is_active() {
            continue;
        }
        match *key {
            ContactKey::Body { a, b } => {
                for (this, other) in [(a as usize, b as usize), (b as usize, a as usize)] {
                    let moving = matches!(
                        world.bodies[other].motion,
                        crate::dynamics::Motion::Prescribed { .. }
                    );
                    if world.bodies[this].is_dynamic() && moving {
                        make_restless(&mut world.sleep, this, &mut counts);
                    }
                }
            }
            ContactKey::Wall { body, wall } => {
                if world.walls[wall as usize].velocity != crate::math::Vector::zeros() {
                    make_restless(&mut world.sleep, body as usize, &mut counts);
                }
            }
        }
    }
    build_islands(world, parent);
    // An island is ready when every dynamic member is asleep or calm long enough.
    ready.clear();
    ready.resize(n, true);
    for i in 0..n {
        if !world.bodies[i].is_dynamic() {
            continue;
        }
        let root = find(parent, i as u32) as usize;
        let member_ready = world.sleep.asleep[i] || world.sleep.calm_steps[i] >= params.steps;
        ready[root] &= member_ready;
    }
    let mut removed = 0.0;
    for i in 0..n {
        if !world.bodies[i].is_dynamic() {
            continue;
        }
        let root = find(parent, i as u32) as usize;
        let sleep = &mut world.sleep;
        if ready[root] {
            if !sleep.asleep[i] {
                let body = &mut world.bodies[i];
                removed += body.translational_kinetic_energy() + body.rotational_kinetic_energy();
                body.velocity = crate::math::Vector::zeros();
                body.angular_momentum = crate::math::Vector::zeros();
                sleep.asleep[i] = true;
                sleep.sleeping += 1;
                counts.fell_asleep += 1;
            }
        } else if sleep.asleep[i] {
            sleep.asleep[i] = false;
            sleep.calm_steps[i] = 0;
            sleep.sleeping -= 1;
            counts.woken += 1;
        }
    }
    world.ledger.removed_by_sleeping += removed;
    counts
}
