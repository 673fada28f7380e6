//! The check of the time step during the run: the motion the scene actually has, against the motion the
//! step was chosen for.
//!
//! The time step is chosen at load against a stability limit that depends on the impact speed the scene
//! declares (`characteristic_speed`, see [`crate::scene::time_step`]): a stiffening law (n > 1) grows
//! stiffer at the deeper overlap of a faster impact, and a step stable at the declared speed is not at
//! a faster one. After each step this check reads the state (it writes nothing, so the trajectory is
//! the same bits with it on or off) and tests three things, as LIGGGHTS' `fix check/timestep/gran` and
//! the "dangerous builds" of LAMMPS/LIGGGHTS neighbour lists do:
//!
//! 1. **Approach speed.** The largest approach speed v_c at which the step Δt is still within the
//!    stability limit is found once per world and step ([`critical_speed`]: the load-time limit, same
//!    lightest masses and laws, solved for the speed instead of the step). No two bodies approach faster
//!    than the sum of the two largest body speeds (a body and a wall: the largest body speed plus the
//!    fastest wall's), so while that bound stays below v_c nothing more is done. Only when it does not
//!    are the listed pairs scanned for their approach speed along the line of centres (along the wall
//!    normal for a wall): a pair closing faster than v_c is a finding, named with its speed, v_c and the
//!    limit at its speed. Listed pairs are those within the contact reach plus the skin, so a fast impact
//!    is caught in the step before the contact or in its first step.
//! 2. **Dangerous moves.** Bodies whose move in one step, |v| Δt, exceeds half the skin (the margin each
//!    body has between list builds) are counted ([`super::StepCounters::dangerous_moves`]). The lists
//!    are checked every step, so no pair is missed at the evaluated positions; a count above zero says
//!    the skin no longer saves list builds, and how often bodies move by large steps.
//! 3. **Tunnelling.** Two bodies apart at one step (centres at least r_A + r_B apart for spheres) can
//!    have a centre inside the other at the next only if they closed by more than the radius of the one
//!    that entered; no two bodies close by more than (v₁ + v₂) Δt in one step (v₁, v₂ the two largest
//!    body speeds; v₁ plus the fastest wall's speed against a wall). When that exceeds the smallest
//!    particle radius (bounding radius: the inradius of a sphere, more than that of a polyhedron), a
//!    centre can pass into another body between two contact queries with no pair ever overlapping (the
//!    exact, O(N²) test of this is [`crate::world::tunnelling`]): a finding, named with the fastest
//!    body, its speed and its move. Two bodies far apart that each move half the smallest radius per
//!    step are flagged as well: the bound does not look at where they are.
//!
//! A finding stops the step with [`StepError::TimeStep`] ([`TimeStepCheck::Stop`], the default), is
//! reported in [`super::StepReport::time_step_findings`] ([`TimeStepCheck::Warn`]), or the check is not
//! run ([`TimeStepCheck::Off`], for scenes unstable on purpose).
//!
//! Cost: one pass over the bodies' velocities per step (a read of each velocity, a squared norm and two
//! comparisons), and a pass over the listed pairs only in the steps where the speed bound exceeds v_c.
//! Folding the pair scan into every step's pair loop would cost every pair every step for a test that
//! normal runs never need; the speed bound decides in O(1) after the body pass. Measured (callgrind, one
//! thread, `examples/sphere_bed_speed.rs --check stop|off`, sphere bed a, 3001 spheres): 13 instructions
//! per sphere and step, +1.05 % of a flat-layout step without the ledger (500 steps) and +0.39 % of a
//! general step with the ledger (200 steps).
//! The rotation of the bodies is left out of the approach speed (the load-time guard also takes the
//! impact speed as the speed of the centres).

use crate::math::{Point, Real, Vector};
use crate::scene::time_step::{critical_speed, limit_at, pair_estimates, BodyFacts, PairEstimate};

use super::super::contact_store::ContactKey;
use super::super::world::{Wall, World};
use super::counters::StepCounters;
use super::findings::{TimeStepCheck, TimeStepFinding};
use super::report::StepError;

/// What the check keeps of a world between steps: the pair estimates of the load-time guard, the
/// critical approach speed of the step, and the smallest particle radius; formed again when the world's
/// size or the step changes.
#[derive(Clone, Debug, Default)]
pub(crate) struct Guard {
    key: Option<(usize, usize, usize, u64)>,
    estimates: Vec<PairEstimate>,
    kappa: Real,
    critical_speed: Real,
    smallest_radius: Real,
}

impl Guard {
    /// The guard of `world` stepped with `dt`.
    pub(crate) fn of(world: &World, dt: Real) -> Guard {
        let mut g = Guard::default();
        g.ensure(world, dt);
        g
    }

    /// Forms the guard again when the world's body, wall or material count or the step changed.
    pub(crate) fn ensure(&mut self, world: &World, dt: Real) {
        let key = (
            world.bodies.len(),
            world.walls.len(),
            world.materials.len(),
            dt.to_bits(),
        );
        if self.key == Some(key) {
            return;
        }
        let facts = world.bodies.iter().enumerate().map(|(i, b)| BodyFacts {
            material: world.material_of[i],
            dynamic: b.is_dynamic(),
            mass: b.mass,
            smallest_moment: b.inertia.0.min(),
            bounding_radius: world.radii[i],
            shape: world.shape(i),
        });
        let walls = world.walls.iter().map(|w| w.material);
        let (estimates, kappa) = pair_estimates(&world.materials, facts, walls);
        self.critical_speed = critical_speed(&estimates, kappa, dt);
        self.estimates = estimates;
        self.kappa = kappa;
        self.smallest_radius = world.radii.iter().copied().fold(Real::INFINITY, Real::min);
        self.key = Some(key);
    }
}

/// The state the check reads, by body index: centre (m), velocity (m/s) and bounding radius (m).
pub(crate) struct Bodies<'a, S: Fn(usize) -> (Point, Vector, Real)> {
    pub(crate) len: usize,
    pub(crate) state: S,
    pub(crate) names: &'a [String],
    pub(crate) walls: &'a [Wall],
    /// Half the skin of the lists (m).
    pub(crate) margin: Real,
}

/// The two largest body speeds (m/s) and the body of the largest.
struct Fastest {
    first: Real,
    body: usize,
    second: Real,
}

fn fastest<S: Fn(usize) -> (Point, Vector, Real)>(bodies: &Bodies<'_, S>) -> Fastest {
    let (mut first, mut body, mut second) = (0.0, 0, 0.0);
    for i in 0..bodies.len {
        let v2 = (bodies.state)(i).1.norm_squared();
        if v2 > second {
            if v2 > first {
                second = first;
                first = v2;
                body = i;
            } else {
                second = v2;
            }
        }
    }
    Fastest {
        first: first.sqrt(),
        body,
        second: second.sqrt(),
    }
}

/// The check of the module docs after a step to `step` of size `dt`: the dangerous moves counted in
/// `counters`; a finding returned as the error ([`TimeStepCheck::Stop`]) or in `findings`
/// ([`TimeStepCheck::Warn`]). `pairs` lists the candidate pairs, read only when the speed bound asks.
#[allow(clippy::too_many_arguments)]
pub(crate) fn check<S, P>(
    mode: TimeStepCheck,
    guard: &Guard,
    dt: Real,
    step: u64,
    bodies: &Bodies<'_, S>,
    pairs: impl FnOnce() -> P,
    counters: &mut StepCounters,
    findings: &mut Vec<TimeStepFinding>,
) -> Result<(), StepError>
where
    S: Fn(usize) -> (Point, Vector, Real),
    P: Iterator<Item = ContactKey>,
{
    if mode == TimeStepCheck::Off {
        return Ok(());
    }
    let top = fastest(bodies);
    if top.first * dt > bodies.margin {
        counters.dangerous_moves += (0..bodies.len)
            .filter(|&i| (bodies.state)(i).1.norm() * dt > bodies.margin)
            .count() as u64;
    }
    let mut found = Vec::new();
    let wall_speed = bodies
        .walls
        .iter()
        .map(|w| w.velocity.norm())
        .fold(0.0, Real::max);
    let closing_speed = top.first + top.second.max(wall_speed);
    if closing_speed > guard.critical_speed {
        if let Some((key, speed)) = fastest_approach(bodies, pairs()) {
            if speed > guard.critical_speed {
                found.push(TimeStepFinding::FastApproach {
                    key,
                    pair: pair_name(bodies, key),
                    speed,
                    critical_speed: guard.critical_speed,
                    limit: limit_at(&guard.estimates, guard.kappa, speed),
                    dt,
                });
            }
        }
    }
    if closing_speed * dt > guard.smallest_radius {
        found.push(TimeStepFinding::Tunnelling {
            body: top.body,
            name: bodies.names[top.body].clone(),
            speed: top.first,
            displacement: top.first * dt,
            closing: closing_speed * dt,
            smallest_radius: guard.smallest_radius,
        });
    }
    match (mode, found.is_empty()) {
        (_, true) => Ok(()),
        (TimeStepCheck::Stop, false) => Err(StepError::TimeStep {
            step,
            finding: Box::new(found.swap_remove(0)),
        }),
        _ => {
            findings.extend(found);
            Ok(())
        }
    }
}

/// The listed pair that meets fastest, and its normal speed (m/s): the approach speed −(v_B − v_A)·n,
/// n the unit vector from A's centre to B's or the wall's normal (A the wall), of a pair still apart;
/// its magnitude for a pair within reach (bounding spheres, or the bounding sphere and the wall, that
/// overlap), whose rebound out of a contact too stiff for the step is as fast as the impact that drove
/// it in (a fast pair may reach and leave a deep overlap between two checks).
fn fastest_approach<S: Fn(usize) -> (Point, Vector, Real)>(
    bodies: &Bodies<'_, S>,
    pairs: impl Iterator<Item = ContactKey>,
) -> Option<(ContactKey, Real)> {
    let mut best: Option<(ContactKey, Real)> = None;
    for key in pairs {
        let speed = match key {
            ContactKey::Body { a, b } => {
                let (xa, va, ra) = (bodies.state)(a as usize);
                let (xb, vb, rb) = (bodies.state)(b as usize);
                let d = xb - xa;
                let relative = vb - va;
                let distance = d.norm();
                if distance == 0.0 {
                    relative.norm()
                } else {
                    normal_speed(-relative.dot(&d) / distance, distance < ra + rb)
                }
            }
            ContactKey::Wall { body, wall } => {
                let w = &bodies.walls[wall as usize];
                let (x, v, r) = (bodies.state)(body as usize);
                let reached = w.signed_distance(&x) < r;
                normal_speed((w.velocity - v).dot(&w.normal_world()), reached)
            }
        };
        if best.is_none_or(|(_, s)| speed > s) {
            best = Some((key, speed));
        }
    }
    best
}

/// The speed a pair is judged by: its approach speed while apart, |v_n| within reach.
#[inline]
fn normal_speed(approach: Real, within_reach: bool) -> Real {
    if within_reach {
        approach.abs()
    } else {
        approach
    }
}

fn pair_name<S: Fn(usize) -> (Point, Vector, Real)>(
    bodies: &Bodies<'_, S>,
    key: ContactKey,
) -> String {
    match key {
        ContactKey::Body { a, b } => format!(
            "body {a} ('{}') and body {b} ('{}')",
            bodies.names[a as usize], bodies.names[b as usize]
        ),
        ContactKey::Wall { body, wall } => format!(
            "body {body} ('{}') and wall {wall} ('{}')",
            bodies.names[body as usize], bodies.walls[wall as usize].name
        ),
    }
}
