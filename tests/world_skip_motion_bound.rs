//! The two skips that stand for the cached-axis test of a polyhedron pair (`polydem::world::skips`):
//! - motion bound (`Skips::motion_bound`, `still_separated`): a pair whose cached separating axis proved a
//!   gap keeps that proof, and the step skips the test while the relative motion since cannot have closed
//!   the gap;
//! - warm overlap (`Skips::warm_overlap`, `polydem::contact::warm_overlap_with`): a pair that overlapped
//!   at its last query runs its warm-started EPA first, and when that proves the overlap the test (which
//!   cannot reject an overlapping pair) is skipped.
//!
//! - The bound is conservative: over random pairs of random hulls and random relative motions of the order
//!   of the proved gap (translations and rotations of either body), every pair the bound skips is one the
//!   cached-axis test rejects at that pose, and the exact query (GJK's distance, and the SAT oracle for
//!   one in eight) finds it separated by more than the touching band. The motions straddle the bound, so both outcomes occur (counted and required).
//! - The warm overlap is conservative: over random overlapping pairs moved by random amounts up to their
//!   overlap, whenever the warm start proves the overlap, the cached-axis test along the pair's cached axis
//!   and along random axes fails, and the answer is the full query's, bit for bit.
//! - Both skips are exact in a step: a polyhedral bed settling for 1500 steps with either skip on and off
//!   ends with bit-identical bodies, loads, wall forces and energy ledger, the same contact-store forces,
//!   histories and warm-start directions, and the same narrow-phase work apart from the skipped tests
//!   (every motion-bound skip replaces one cached-axis rejection; GJK and EPA runs are the same).

#[path = "support/bed.rs"]
mod bed;

use polydem::contact::{
    query_polyhedra, query_polyhedra_cached, query_with, sat_polyhedra, warm_overlap_with,
    ContactKind, ContactTolerances, EpaScratch, PairCache, QueryCounters,
};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{ConvexPolyhedron, Shape};
use polydem::world::skips::{reject_by_cached_axis, still_separated, SeparationBound};
use polydem::world::{step, Skips, StepScratch, World};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::sync::Arc;

fn random_unit(rng: &mut ChaCha8Rng) -> Vector {
    loop {
        let v = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

/// A hull of `points` random points on a randomly stretched sphere of radius `radius` (centroid frame).
fn random_hull(rng: &mut ChaCha8Rng, radius: Real, points: usize) -> ConvexPolyhedron {
    let stretch = Vector::new(
        rng.random_range(0.3..1.0),
        rng.random_range(0.3..1.0),
        rng.random_range(0.3..1.0),
    );
    let pts: Vec<Point> = (0..points)
        .map(|_| Point::from(random_unit(rng).component_mul(&stretch) * radius))
        .collect();
    ConvexPolyhedron::from_points(&pts)
        .expect("random hull of points on a sphere")
        .0
}

/// Two random hulls of 6–39 points, A of diameter `size`, B of 0.3–1.5 times that.
fn random_pair(rng: &mut ChaCha8Rng, size: Real) -> (ConvexPolyhedron, ConvexPolyhedron) {
    let points = rng.random_range(6..40);
    let a = random_hull(rng, 0.5 * size, points);
    let (scale, points) = (rng.random_range(0.3..1.5), rng.random_range(6..40));
    let b = random_hull(rng, 0.5 * size * scale, points);
    (a, b)
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Rotation {
    Rotation::from_scaled_axis(random_unit(rng) * rng.random_range(0.0..std::f64::consts::PI))
}

/// `pose` moved by a translation of length `t` and a rotation by `angle` about an axis through the point
/// `pivot` (world), both in random directions.
fn moved(rng: &mut ChaCha8Rng, pose: &Pose, t: Real, angle: Real, pivot: &Point) -> Pose {
    let turn = Rotation::from_scaled_axis(random_unit(rng) * angle);
    let centre = Point::from(pose.translation.vector);
    let centre = pivot + turn * (centre - pivot) + random_unit(rng) * t;
    Pose::from_parts(centre.coords.into(), turn * pose.rotation)
}

#[test]
fn motion_bound_skips_only_pairs_the_cached_axis_rejects_and_that_are_separated() {
    let mut rng = ChaCha8Rng::seed_from_u64(61);
    let tol = ContactTolerances::default();
    let mut scratch = EpaScratch::default();
    let (mut proofs, mut skipped, mut kept) = (0usize, 0usize, 0usize);
    let mut tightest: Real = Real::INFINITY;
    for trial in 0..400 {
        let size = 10f64.powf(rng.random_range(-3.0..1.0));
        let (a, b) = random_pair(&mut rng, size);
        // B at a random distance around touching from A, far from the origin (round-off of the coordinates).
        let far = Vector::new(1.0, -2.0, 0.5) * size * rng.random_range(0.0..100.0);
        let pos1 = Pose::from_parts(far.into(), random_rotation(&mut rng));
        let reach = (a.bounding_radius() + b.bounding_radius()) * rng.random_range(0.5..1.2);
        let pos2 = Pose::from_parts(
            (far + random_unit(&mut rng) * reach).into(),
            random_rotation(&mut rng),
        );
        // The warm start of a separated pair (GJK's direction), then the cached-axis test that proves it.
        let mut cache = PairCache::default();
        let mut counters = QueryCounters::default();
        let g = query_polyhedra_cached(
            &pos1,
            &a,
            &pos2,
            &b,
            &mut cache,
            &mut scratch,
            &mut counters,
        );
        if g.kind != ContactKind::Separated {
            continue;
        }
        let mut bound = SeparationBound::default();
        let pos12 = pos1.inv_mul(&pos2);
        if reject_by_cached_axis(
            &pos1,
            &pos12,
            &a,
            &b,
            &tol,
            &mut cache,
            &mut bound,
            &mut counters,
        )
        .is_none()
            || bound.gap <= 0.0
        {
            continue;
        }
        proofs += 1;
        let gap = bound.gap;
        for _ in 0..50 {
            // Motions of the order of the gap, split at random between translation and rotation, of either
            // body, about its centre or about another point.
            let budget = gap * rng.random_range(0.0..1.5);
            let share = rng.random_range(0.0..1.0);
            let (mut p1, mut p2) = (pos1, pos2);
            let pivot_of = |rng: &mut ChaCha8Rng, p: &Pose| {
                if rng.random_bool(0.5) {
                    Point::from(p.translation.vector)
                } else {
                    Point::from(p.translation.vector) + random_unit(rng) * size
                }
            };
            if rng.random_bool(0.7) {
                let pivot = pivot_of(&mut rng, &p2);
                let r = b.bounding_radius() + (pivot - Point::from(p2.translation.vector)).norm();
                p2 = moved(
                    &mut rng,
                    &p2,
                    budget * share,
                    budget * (1.0 - share) / r,
                    &pivot,
                );
            }
            if rng.random_bool(0.7) {
                let pivot = pivot_of(&mut rng, &p1);
                let r = reach + 2.0 * size;
                p1 = moved(
                    &mut rng,
                    &p1,
                    budget * share,
                    budget * (1.0 - share) / r,
                    &pivot,
                );
            }
            let pos12_now = p1.inv_mul(&p2);
            let mut c = QueryCounters::default();
            if !still_separated(&bound, &pos12_now, &a, &b, &tol, &mut c) {
                kept += 1;
                continue;
            }
            skipped += 1;
            assert_eq!(c.motion_bound_skips, 1, "a skip is counted");
            let (mut cache_now, mut bound_now) = (cache, bound);
            let rejected = reject_by_cached_axis(
                &p1,
                &pos12_now,
                &a,
                &b,
                &tol,
                &mut cache_now,
                &mut bound_now,
                &mut QueryCounters::default(),
            );
            let Some(at_axis) = rejected else {
                panic!(
                    "trial {trial}: the bound skipped a pair the cached-axis test keeps (proved gap {gap:e} m, size {size:e} m, poses {p1:?} {p2:?})"
                );
            };
            // The exact answer: GJK's distance (exact on polytopes), and the SAT oracle for one in eight.
            let exact = if skipped % 8 == 0 {
                sat_polyhedra(&p1, &a, &p2, &b)
            } else {
                query_polyhedra(&p1, &a, &p2, &b)
            };
            let touch = tol.touching * a.length_scale().max(b.length_scale());
            assert!(
                exact.kind == ContactKind::Separated && exact.distance > touch,
                "trial {trial}: skipped pair is not separated by the exact query: {exact:?} (band {touch:e} m, proved gap {gap:e} m, poses {p1:?} {p2:?})"
            );
            assert!(
                at_axis.distance <= exact.distance * (1.0 + 1e-9) + 1e-12 * size,
                "trial {trial}: the gap along the axis {} exceeds the exact distance {} (size {size:e})",
                at_axis.distance,
                exact.distance
            );
            // How much of the proved gap the skipped pairs used (the bound is not vacuous).
            tightest = tightest.min(at_axis.distance / gap);
        }
    }
    eprintln!(
        "motion bound: {proofs} proofs, {skipped} motions skipped, {kept} kept for the test; smallest remaining gap along the axis / proved gap {tightest:.3}"
    );
    assert!(
        proofs >= 100 && skipped >= 1000 && kept >= 1000,
        "too few cases to test anything: proofs {proofs} (≥ 100), skipped {skipped} (≥ 1000), kept {kept} (≥ 1000)"
    );
    assert!(
        tightest < 0.5,
        "the skipped motions never used half of the proved gap (smallest remaining fraction {tightest}): the test does not reach the bound"
    );
}

#[test]
fn warm_overlap_answers_only_pairs_the_cached_axis_cannot_reject_and_as_the_full_query() {
    let mut rng = ChaCha8Rng::seed_from_u64(62);
    let tol = ContactTolerances::default();
    let mut scratch = EpaScratch::default();
    let (mut hits, mut misses) = (0usize, 0usize);
    for trial in 0..300 {
        let size = 10f64.powf(rng.random_range(-3.0..1.0));
        let (a, b) = random_pair(&mut rng, size);
        let (a, b) = (Arc::new(a), Arc::new(b));
        let (sa, sb) = (Shape::Polyhedron(a.clone()), Shape::Polyhedron(b.clone()));
        let far = Vector::new(-1.0, 0.5, 2.0) * size * rng.random_range(0.0..100.0);
        let pos1 = Pose::from_parts(far.into(), random_rotation(&mut rng));
        let reach = (a.bounding_radius() + b.bounding_radius()) * rng.random_range(0.2..0.8);
        let pos2 = Pose::from_parts(
            (far + random_unit(&mut rng) * reach).into(),
            random_rotation(&mut rng),
        );
        let mut cache = PairCache::default();
        let g = query_with(
            &pos1,
            &sa,
            &pos2,
            &sb,
            &tol,
            &mut cache,
            &mut scratch,
            &mut QueryCounters::default(),
        )
        .expect("polyhedra");
        if g.kind != ContactKind::Overlap || !cache.has_face {
            continue;
        }
        for _ in 0..20 {
            // Relative motions up to about twice the overlap: some pairs separate, some stay in contact.
            let budget = g.depth * rng.random_range(0.0..2.0);
            let share = rng.random_range(0.0..1.0);
            let p2 = moved(
                &mut rng,
                &pos2,
                budget * share,
                budget * (1.0 - share) / b.bounding_radius(),
                &Point::from(pos2.translation.vector),
            );
            let pos12 = pos1.inv_mul(&p2);
            let (mut warm_cache, mut full_cache) = (cache, cache);
            let mut warm_counters = QueryCounters::default();
            let Some(warm) = warm_overlap_with(
                &pos1,
                &pos12,
                &a,
                &p2,
                &b,
                &tol,
                &mut warm_cache,
                &mut scratch,
                &mut warm_counters,
            ) else {
                misses += 1;
                assert_eq!(warm_cache, cache, "trial {trial}: a miss changed the cache");
                assert_eq!(
                    warm_counters,
                    QueryCounters::default(),
                    "trial {trial}: a miss counted"
                );
                continue;
            };
            hits += 1;
            // The cached-axis test cannot reject the pair: along the cached axis and along random axes.
            for k in 0..5 {
                let mut probe = cache;
                if k > 0 {
                    probe.dir = random_unit(&mut rng) * size;
                }
                let mut bound = SeparationBound::default();
                let rejected = reject_by_cached_axis(
                    &pos1,
                    &pos12,
                    &a,
                    &b,
                    &tol,
                    &mut probe,
                    &mut bound,
                    &mut QueryCounters::default(),
                );
                assert!(
                    rejected.is_none(),
                    "trial {trial}: the warm start proved an overlap of {} m but the axis {:?} rejects the pair: {rejected:?}",
                    warm.depth,
                    probe.dir
                );
            }
            // The same answer, cache and counters as the full query.
            let mut full_counters = QueryCounters::default();
            let full = query_with(
                &pos1,
                &sa,
                &p2,
                &sb,
                &tol,
                &mut full_cache,
                &mut scratch,
                &mut full_counters,
            )
            .expect("polyhedra");
            assert_eq!(
                (warm, warm_cache, warm_counters),
                (full, full_cache, full_counters),
                "trial {trial}: the warm overlap differs from the full query"
            );
        }
    }
    eprintln!("warm overlap: {hits} hits, {misses} misses");
    assert!(
        hits >= 1000 && misses >= 50,
        "too few cases to test anything: hits {hits} (≥ 1000), misses {misses} (≥ 50)"
    );
}

const STEPS: usize = 1500;

/// Runs `bed` for `STEPS` steps with `skips`; returns the world and the summed narrow-phase counters.
fn run(mut bed: bed::Bed, skips: Skips) -> (World, QueryCounters) {
    bed.params.skips = skips;
    let mut scratch = StepScratch::default();
    let mut c = QueryCounters::default();
    for _ in 0..STEPS {
        let r = step(&bed.params, &mut bed.world, &mut scratch).expect("step");
        c.merge(&r.counters.query);
    }
    (bed.world, c)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn bed_spec() -> bed::BedSpec {
    // Polyhedra only, stacked nearly in contact with random velocities and spins: they collide and
    // settle; many pairs stay separated along their cached axes for many steps, many stay in contact.
    bed::BedSpec {
        gap: 0.0,
        speed: 0.5,
        ..bed::BedSpec::rocks([5, 5, 6], 0, 17)
    }
}

#[test]
fn motion_bound_on_and_off_give_bit_identical_trajectories() {
    let spec = bed_spec();
    let (on, c_on) = run(bed::build(&spec), Skips::all(true));
    let (off, c_off) = run(
        bed::build(&spec),
        Skips {
            motion_bound: false,
            ..Skips::all(true)
        },
    );
    eprintln!(
        "motion bound on: {} skips, {} cached-axis rejections; off: {} rejections",
        c_on.motion_bound_skips, c_on.cached_axis_rejections, c_off.cached_axis_rejections
    );
    assert!(
        c_on.motion_bound_skips > 5000 && c_off.motion_bound_skips == 0,
        "skips on {} (> 5000), off {} (0)",
        c_on.motion_bound_skips,
        c_off.motion_bound_skips
    );
    // Every skip stands for a rejection of the test; everything else ran the same.
    assert_eq!(
        c_on.motion_bound_skips + c_on.cached_axis_rejections,
        c_off.cached_axis_rejections,
        "skips + rejections with the skip on must equal the rejections with it off"
    );
    assert_same_run("motion bound", (&on, &c_on), (&off, &c_off));
}

#[test]
fn warm_overlap_on_and_off_give_bit_identical_trajectories() {
    let spec = bed_spec();
    let (on, c_on) = run(bed::build(&spec), Skips::all(true));
    let (off, c_off) = run(
        bed::build(&spec),
        Skips {
            warm_overlap: false,
            ..Skips::all(true)
        },
    );
    eprintln!(
        "warm overlap: {} warm hits (on), {} (off)",
        c_on.epa_warm_hits, c_off.epa_warm_hits
    );
    assert!(
        c_on.epa_warm_hits > 5000,
        "too few warm-start hits to test anything: {}",
        c_on.epa_warm_hits
    );
    assert_eq!(
        (c_on.cached_axis_rejections, c_on.motion_bound_skips),
        (c_off.cached_axis_rejections, c_off.motion_bound_skips),
        "rejections and motion-bound skips must not change"
    );
    assert_same_run("warm overlap", (&on, &c_on), (&off, &c_off));
}

/// The two runs (world, counters) of a skip on and off end in the same state (see the module docs).
fn assert_same_run(
    label: &str,
    (on, c_on): (&World, &QueryCounters),
    (off, c_off): (&World, &QueryCounters),
) {
    let same_work = |c: &QueryCounters| {
        [
            c.polyhedron_polyhedron,
            c.polyhedron_plane,
            c.bounding_sphere_rejections,
            c.gjk_runs,
            c.gjk_iterations,
            c.epa_runs,
            c.epa_iterations,
            c.epa_warm_hits,
            c.overlapping,
            c.touching,
            c.separated,
        ]
    };
    assert_eq!(
        same_work(c_on),
        same_work(c_off),
        "{label}: queries, GJK/EPA work and results differ with the skip on ({c_on:?}) and off ({c_off:?})"
    );
    for (i, (a, b)) in on.bodies().iter().zip(off.bodies()).enumerate() {
        for (name, x, y) in [
            ("position", a.position.coords, b.position.coords),
            ("velocity", a.velocity, b.velocity),
            ("angular momentum", a.angular_momentum, b.angular_momentum),
            (
                "contact force",
                on.loads().forces()[i],
                off.loads().forces()[i],
            ),
            (
                "contact torque",
                on.loads().torques()[i],
                off.loads().torques()[i],
            ),
        ] {
            assert_eq!(
                bits(x.as_slice()),
                bits(y.as_slice()),
                "{label}: body {i} {name} differs with the skip on ({x:?}) and off ({y:?}) after {STEPS} steps"
            );
        }
        assert_eq!(
            bits(a.orientation.coords.as_slice()),
            bits(b.orientation.coords.as_slice()),
            "{label}: body {i} orientation differs: on {:?} off {:?}",
            a.orientation,
            b.orientation
        );
    }
    for (w, (x, y)) in on
        .loads()
        .wall_forces()
        .iter()
        .zip(off.loads().wall_forces())
        .enumerate()
    {
        assert_eq!(
            bits(x.as_slice()),
            bits(y.as_slice()),
            "{label}: wall {w} force differs: on {x:?} off {y:?}"
        );
    }
    let (e_on, e_off) = (on.energy(), off.energy());
    assert_eq!(
        format!("{e_on:?}"),
        format!("{e_off:?}"),
        "{label}: energy ledger differs with the skip on and off"
    );
    // The store: the same pairs, forces, springs and warm starts; only a skipped pair's separated geometry,
    // support hints and kept proof may be older with the skip on.
    assert_eq!(
        on.contacts().keys(),
        off.contacts().keys(),
        "{label}: store keys differ"
    );
    for (k, (s, t)) in on
        .contacts()
        .states()
        .iter()
        .zip(off.contacts().states())
        .enumerate()
    {
        let key = on.contacts().keys()[k];
        assert_eq!(
            (s.history, s.force_on_b, s.damping_force, s.since_step),
            (t.history, t.force_on_b, t.damping_force, t.since_step),
            "{label}: pair {key:?}: history or forces differ"
        );
        assert_eq!(
            (s.cache.dir, s.cache.has_face, s.geometry.kind),
            (t.cache.dir, t.cache.has_face, t.geometry.kind),
            "{label}: pair {key:?}: warm start or contact kind differ"
        );
        if s.geometry.kind != ContactKind::Separated {
            assert_eq!(
                (s.geometry, s.cache),
                (t.geometry, t.cache),
                "{label}: pair {key:?}: geometry of a contact differs"
            );
        }
    }
    assert!(
        c_on.overlapping > 5000,
        "{label}: too few overlapping pair-steps to test anything: {}",
        c_on.overlapping
    );
}
