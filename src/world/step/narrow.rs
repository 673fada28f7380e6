//! Stages 4–5: the narrow phase (one contact query per candidate) fused with the laws, in one pass over
//! the contact store synced to the candidate list.

use crate::contact::contact_polyhedron_plane::plane_polytope_depth;
use crate::contact::{
    contact_plane_sphere, contact_sphere_sphere, query_with, ContactError, ContactTolerances,
    QueryCounters, WallDepth,
};
use crate::math::{Pose, Real};
use crate::shape::Shape;

use super::super::contact_store::{ContactKey, ContactState};
use super::super::energy::ContactWork;
use super::super::parallel::{for_each_chunked, Worker};
use super::super::region_profile::Section;
use super::super::skips;
use super::super::sleeping;
use super::super::timing::{Stage, StageClock};
use super::super::world::World;
use super::counters::StepCounters;
use super::laws::{contact_law, Evaluated, PairInputs};
use super::params::StepParams;
use super::report::StepError;
use super::scratch::StepScratch;
use super::sphere_kernel;

/// What stage 6 needs to know of the pass of stages 4–5.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pass {
    /// Whether the pass ran on the pool (then stage 6 may gather the sums per body).
    pub(super) parallel: bool,
    /// Whether the store's sync created or dropped entries (the frozen sums are rebuilt then).
    pub(super) store_changed: bool,
}

/// Stages 4–5, fused: per candidate, the contact query then (if the shapes overlap) the law, in one pass
/// over the store; the results in `scratch.evaluated`, the picked candidates in the workers.
pub(super) fn stage(
    params: &StepParams,
    world: &mut World,
    scratch: &mut StepScratch,
    counters: &mut StepCounters,
    dt: Real,
    omegas_fresh: bool,
) -> Result<Pass, StepError> {
    // 4–5. Narrow phase and laws, fused: per candidate, the contact query then (if the shapes overlap) the
    // law, in one pass over the store (in parallel, each candidate writing its own store entry and result
    // slot). Frozen candidates keep their last geometry and force (see [`super::super::sleeping`]).
    let mut clock = StageClock::start();
    let step_index = world.step_index;
    // The store is taken out of the world for stages 4–5 so that the queries can read the bodies while
    // writing the per-pair state; it is put back before any return.
    let mut contacts = std::mem::take(&mut world.contacts);
    let sync = clock.serial(Section::SerialStore, || {
        contacts.sync_tagged(
            &scratch.candidates,
            scratch.inputs.candidates_tag,
            step_index,
        )
    });
    counters.contacts_created += sync.created as u64;
    counters.contacts_dropped += sync.dropped as u64;
    let store_changed = sync.created + sync.dropped > 0;
    let n_candidates = scratch.candidates.len();
    let parallel = n_candidates >= params.parallel.min_candidates;
    // Every slot's flags are overwritten below (the rest only for overlapping pairs): no clearing.
    scratch.evaluated.resize(n_candidates, Evaluated::default());
    let world_ref: &World = world;
    let candidates = &scratch.candidates;
    let spheres = gather_spheres(params, world_ref, &mut scratch.spheres, &mut clock);
    let pair = PairInputs {
        world: world_ref,
        isotropic: params.skips.isotropic_rotation,
        omegas: omegas_fresh.then_some(scratch.inputs.omegas.as_slice()),
        models: &scratch.models,
        n_materials: world_ref.materials.len(),
        dt,
        step_index,
        ledger: params.energy_ledger,
    };
    let evaluated = clock.region(Section::Narrow, parallel, || {
        for_each_chunked(
            parallel,
            contacts.states_mut(),
            &mut scratch.evaluated,
            &mut scratch.workers,
            |i, state, out, worker| {
                candidate(params, &pair, spheres, candidates[i], state, out, worker)?;
                // Every evaluated candidate that stage 6 has to sum is listed (serially, in candidate
                // order, there).
                if out.contributes() {
                    worker.picked.push(i as u32);
                }
                Ok(())
            },
        )
    });
    take_worker_counts(&mut scratch.workers, counters);
    world.contacts = contacts;
    evaluated?;
    counters.add(Stage::Narrow, clock.stop());

    Ok(Pass {
        parallel,
        store_changed,
    })
}

/// The sphere path's per-body inputs, gathered once for the pass (see [`super::sphere_kernel`]); `None`
/// when the scene's skips turn the path off.
fn gather_spheres<'a>(
    params: &StepParams,
    world: &World,
    spheres: &'a mut Vec<sphere_kernel::SphereBody>,
    clock: &mut StageClock,
) -> Option<&'a [sphere_kernel::SphereBody]> {
    let parallel_bodies = world.bodies.len() >= params.parallel.min_bodies;
    let gathered = params.skips.sphere_kernel
        && clock.pool(parallel_bodies, || {
            sphere_kernel::gather(
                world,
                params.skips.isotropic_rotation,
                parallel_bodies && rayon::current_num_threads() > 1,
                spheres,
            )
        });
    gathered.then_some(spheres.as_slice())
}

/// Moves the workers' query counts and frozen-pair tallies into the step's counters.
fn take_worker_counts(workers: &mut [Worker], counters: &mut StepCounters) {
    for worker in workers {
        counters.query.merge(&worker.query);
        worker.query = QueryCounters::default();
        counters.frozen_pairs += worker.tally;
    }
}

/// Stages 4–5 for one candidate: kept as it was when frozen (both sides asleep or fixed), else the sphere
/// path when it takes the pair, else the contact query and the law.
#[inline(always)]
fn candidate(
    params: &StepParams,
    pair: &PairInputs,
    spheres: Option<&[sphere_kernel::SphereBody]>,
    key: ContactKey,
    state: &mut ContactState,
    out: &mut Evaluated,
    worker: &mut Worker,
) -> Result<(), StepError> {
    if sleeping::is_frozen_entry(pair.world, key, state) {
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
            pair,
            spheres,
            key,
            state,
            &previous_point,
            out,
            worker,
        ) {
            return done;
        }
    }
    narrow_phase(params, pair.world, key, state, worker).map_err(|source| StepError::Contact {
        step: pair.step_index,
        source,
    })?;
    contact_law(pair, key, state, &previous_point, out)?;
    if out.overlapping {
        exact_wall_depth(params, pair.world, key, out);
    }
    Ok(())
}

/// The overlap statistic of a polyhedron on a wall with the smoothed depth: the exact depth (deepest
/// vertex) instead of the smoothed one the law saw, which falls short of it by up to 0.22 h (h the band;
/// see [`crate::contact::wall_depth`]), so that a body sunk into a wall is reported as sunk.
#[inline]
fn exact_wall_depth(params: &StepParams, world: &World, key: ContactKey, out: &mut Evaluated) {
    let ContactKey::Wall { body, wall } = key else {
        return;
    };
    if !matches!(params.tolerances.wall_depth, WallDepth::Smoothed { .. }) {
        return;
    }
    let body = body as usize;
    if let Shape::Polyhedron(p) = world.shape(body) {
        let wall = &world.walls[wall as usize];
        let pose = world.pose(body);
        let depth = plane_polytope_depth(
            &wall.pose,
            wall.plane.normal(),
            wall.plane.offset(),
            &pose,
            p.as_ref(),
        );
        out.depth = depth;
        out.overlap_ratio = depth / world.length_scale(body);
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
    match key {
        ContactKey::Body { a, b } => {
            body_pair(params, world, (a as usize, b as usize), state, worker)
        }
        ContactKey::Wall { body, wall } => {
            wall_pair(params, world, body as usize, wall as usize, state, worker)
        }
    }
}

/// [`narrow_phase`] for bodies `a` < `b`: the bounding-sphere rejection, the sphere–sphere closed form,
/// the polyhedral skips, then the general query.
#[inline]
fn body_pair(
    params: &StepParams,
    world: &World,
    (a, b): (usize, usize),
    state: &mut ContactState,
    worker: &mut Worker,
) -> Result<(), ContactError> {
    let tol = &params.tolerances;
    let (shape_a, shape_b) = (world.shape(a), world.shape(b));
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
    let (pose_a, pose_b) = (world.pose(a), world.pose(b));
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
    general_query(tol, (&pose_a, shape_a), (&pose_b, shape_b), state, worker)
}

/// [`narrow_phase`] for a body and a wall: the bounding-sphere rejection, the plane–sphere closed form,
/// then the general query with the wall's plane as shape A.
#[inline]
fn wall_pair(
    params: &StepParams,
    world: &World,
    body: usize,
    wall: usize,
    state: &mut ContactState,
    worker: &mut Worker,
) -> Result<(), ContactError> {
    let tol = &params.tolerances;
    let wall = &world.walls[wall];
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
    let wall_shape = Shape::Plane(wall.plane);
    let body_pose = world.pose(body);
    general_query(
        tol,
        (&wall.pose, &wall_shape),
        (&body_pose, world.shape(body)),
        state,
        worker,
    )
}

/// The dispatcher's query of shapes A and B at their poses, with the pair's cache.
#[inline]
fn general_query(
    tol: &ContactTolerances,
    (pose_a, shape_a): (&Pose, &Shape),
    (pose_b, shape_b): (&Pose, &Shape),
    state: &mut ContactState,
    worker: &mut Worker,
) -> Result<(), ContactError> {
    state.geometry = query_with(
        pose_a,
        shape_a,
        pose_b,
        shape_b,
        tol,
        &mut state.cache,
        &mut worker.epa,
        &mut worker.query,
    )?;
    Ok(())
}
