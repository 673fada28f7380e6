//! Stage 6: the per-body sums of the forces and torques in candidate order, the walls' forces, the ledger
//! terms and the report (the state at the end of the step: an initial evaluation's findings are replaced
//! by those of the step's own evaluation).
//!
//! Forces and torques on the bodies are summed in candidate order: on one thread by a scatter over the
//! candidates (one sequential pass); on several per body over its pairs (the same additions in the same
//! order: the same bits; it reads each result twice, so it pays only in parallel). The sums can wait for
//! the pass of stages 7–8 when nothing reads the loads before it: no frozen contributions to add, no
//! prescribed body's power, no sleeping check (the caller's choice).

use crate::math::{Real, Vector};

use super::super::contact_store::{BodyAdjacency, ContactKey};
use super::super::parallel::{for_each_item_pair, Worker};
use super::super::region_profile::Section;
use super::super::sleeping::FrozenLoads;
use super::super::timing::{Stage, StageClock};
use super::super::world::{Loads, World};
use super::laws::Evaluated;
use super::ledger::external_power;
use super::narrow::Pass;
use super::params::StepParams;
use super::report::{OverlapWarning, StepReport};
use super::scratch::StepScratch;

/// Stage 6 after the pass `pass` of stages 4–5; with `defer_gather` a parallel gather may be left to the
/// pass of 7–8 ([`StepScratch::deferred_gather`]).
pub(super) fn stage(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    report: &mut StepReport,
    pass: Pass,
    defer_gather: bool,
) {
    let mut clock = StageClock::start();
    let profile_sums = clock.serial_start();
    report.contacts = 0;
    report.max_overlap_ratio = 0.0;
    report.overlap_warnings.clear();
    let n = world.bodies.len();
    if world.sleep.sleeping > 0 {
        scratch
            .frozen
            .ensure(world, pass.store_changed, params.overlap_warning_fraction);
    }
    let loads = &mut world.loads;
    let gather = pass.parallel && rayon::current_num_threads() > 1;
    reset(loads, n, world.walls.len(), gather);
    scratch.deferred_gather =
        gather && defer_gather && !scratch.any_prescribed && world.sleep.sleeping == 0;
    if gather && !scratch.deferred_gather {
        // The rows are rebuilt (serially) after a sync that changed the keys.
        let adjacency = world.contacts.body_adjacency(n);
        let evaluated = &scratch.evaluated;
        clock.region(Section::Gather, true, || {
            for_each_item_pair(
                true,
                &mut loads.forces,
                &mut loads.torques,
                |i, force, torque| sum_body_loads(adjacency, evaluated, i, force, torque),
            )
        });
    }
    let picked = Picked {
        workers: &scratch.workers,
        candidates: &scratch.candidates,
        evaluated: &scratch.evaluated,
        warning_fraction: params.overlap_warning_fraction,
        gather,
    };
    match world.counted.as_deref() {
        None => sum_picked(&picked, |_| true, loads, report),
        Some(owned) => sum_picked(&picked, |key| owned[answering_body(key)], loads, report),
    }
    // The frozen contacts, summed once while the sleeping set and the store's pairs stay the same, added
    // after the candidates in both summation modes (the same bits on any number of threads).
    if world.sleep.sleeping > 0 {
        add_frozen(&scratch.frozen, loads, report);
    }
    report.counters.contacts += report.contacts as u64;
    // Power delivered to the system by everything that moves without responding to forces.
    let prescribed = if scratch.any_prescribed {
        world.bodies.as_slice()
    } else {
        &[]
    };
    let counted = world.counted.as_deref();
    let counts_body = |i: usize| counted.is_none_or(|owned| owned[i]);
    loads.external_power = external_power(loads, prescribed, &world.walls, counts_body);
    loads.current = true;
    clock.serial_end(Section::SerialSums, profile_sums);
    report.counters.add(Stage::Accumulate, clock.stop());
}

/// The loads before the sums: `n` bodies, `n_walls` walls, the sums zero. The scatter adds into zeros;
/// the gather writes every body's slot (no clearing pass).
fn reset(loads: &mut Loads, n: usize, n_walls: usize, gather: bool) {
    if !gather {
        loads.forces.clear();
        loads.torques.clear();
    }
    loads.forces.resize(n, Vector::zeros());
    loads.torques.resize(n, Vector::zeros());
    loads.wall_forces.clear();
    loads.wall_forces.resize(n_walls, Vector::zeros());
    loads.elastic_potential = 0.0;
    loads.damping_work = 0.0;
    loads.friction_dissipation = 0.0;
    loads.tangential_stiffness_work = 0.0;
}

/// The candidates stages 4–5 picked and what stage 6 needs to sum them.
struct Picked<'a> {
    workers: &'a [Worker],
    candidates: &'a [ContactKey],
    evaluated: &'a [Evaluated],
    warning_fraction: Real,
    /// Whether the bodies' forces and torques are gathered per body (else scattered here).
    gather: bool,
}

/// The body whose part answers for a pair in a split world: a body pair's lower body, a body–wall pair's
/// body ([`super::super::energy_share`]).
#[inline]
fn answering_body(key: &ContactKey) -> usize {
    match *key {
        ContactKey::Body { a, .. } => a as usize,
        ContactKey::Wall { body, .. } => body as usize,
    }
}

/// The serial sums in candidate order: the ledger terms, the report, the walls' forces and (on one thread,
/// `!gather`) the bodies' forces and torques by a scatter. The energy sums and the walls' forces take the
/// pairs `counts` counts (every pair but in a part of a split world); the bodies' forces take every pair.
///
/// They visit only the candidates stages 4–5 picked (overlapping, or with ledger terms: a pair that opens
/// in this step books its release), in candidate order: the others would add nothing (their ledger terms
/// are ±0, and a sum that starts at +0 is unchanged by adding ±0), so the sums have the same bits as over
/// all candidates, for any number of threads (see [`Worker::picked`]).
#[inline]
fn sum_picked(
    p: &Picked,
    counts: impl Fn(&ContactKey) -> bool,
    loads: &mut Loads,
    report: &mut StepReport,
) {
    let picked = p.workers.iter().flat_map(|w| &w.picked);
    for &i in picked {
        let (key, e) = (&p.candidates[i as usize], &p.evaluated[i as usize]);
        let counted = counts(key);
        if counted {
            loads.damping_work += e.work.damping;
            loads.friction_dissipation += e.work.friction;
            loads.tangential_stiffness_work += e.work.stiffness;
        }
        if !e.overlapping {
            // A separated pair contributes nothing (its response slot is stale).
            continue;
        }
        report.contacts += 1;
        report.max_overlap_ratio = report.max_overlap_ratio.max(e.overlap_ratio);
        if e.overlap_ratio > p.warning_fraction {
            report.overlap_warnings.push(OverlapWarning {
                key: *key,
                depth: e.depth,
                ratio: e.overlap_ratio,
            });
        }
        match *key {
            ContactKey::Body { a, b } if !p.gather => {
                loads.forces[a as usize] -= e.force_on_b;
                loads.torques[a as usize] += e.torque_on_a;
                loads.forces[b as usize] += e.force_on_b;
                loads.torques[b as usize] += e.torque_on_b;
            }
            ContactKey::Body { .. } => {}
            ContactKey::Wall { body, wall } => {
                if counted {
                    loads.wall_forces[wall as usize] -= e.force_on_b;
                }
                if !p.gather {
                    loads.forces[body as usize] += e.force_on_b;
                    loads.torques[body as usize] += e.torque_on_b;
                }
            }
        }
        if counted {
            loads.elastic_potential += e.potential;
        }
    }
}

/// The frozen contacts' sums `f` added to the loads and the report.
fn add_frozen(f: &FrozenLoads, loads: &mut Loads, report: &mut StepReport) {
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
