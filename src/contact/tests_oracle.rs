//! Oracle tests: GJK/EPA against the exact SAT answer on seeded random pairs and on the degenerate set.
//!
//! Gate: zero wrong kinds; depth (or distance) error ≤ 1e-10 L + 1e-9 δ; the reported normal is an
//! optimal axis (support-distance overlap along it equals the exact value within the same tolerance);
//! c1 and c2 on the surfaces of A and B within the same tolerance; c1 − c2 = δ n (c2 − c1 = d n when apart).

use super::testing::{random_pose, random_rotation, random_unit, TestPolytope};
use super::*;
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::ConvexPolyhedron;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Largest errors met, relative to the pair's length scale.
#[derive(Default, Debug)]
pub(crate) struct Stats {
    pub pairs: usize,
    pub overlap: usize,
    pub touching: usize,
    pub separated: usize,
    pub fallbacks: usize,
    pub warm_starts: usize,
    pub warm_hits: usize,
    pub max_value_err: Real,
    pub max_normal_err: Real,
    pub max_surface_err: Real,
}

fn overlap_along_world<A: Polytope, B: Polytope>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    n: &Vector,
) -> Real {
    let ha = a
        .vertices()
        .iter()
        .map(|p| n.dot(&(pos1 * p).coords))
        .fold(Real::NEG_INFINITY, Real::max);
    let hb = b
        .vertices()
        .iter()
        .map(|p| -n.dot(&(pos2 * p).coords))
        .fold(Real::NEG_INFINITY, Real::max);
    ha + hb
}

/// Signed distance of a world point to the surface of a polytope (positive outside).
fn surface_distance<P: Polytope>(pos: &Pose, p: &P, x: &Point) -> Real {
    let y = pos.inverse_transform_point(x).coords;
    (0..p.num_faces())
        .map(|i| {
            p.face_normal(i)
                .dot(&(y - p.vertices()[p.face_vertices(i)[0] as usize].coords))
        })
        .fold(Real::NEG_INFINITY, Real::max)
}

pub(crate) fn check_pair<A: Polytope, B: Polytope>(
    ctx: &str,
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    stats: &mut Stats,
) -> Result<(), String> {
    let tol = ContactTolerances::default();
    let oracle = sat_polytopes(pos1, a, pos2, b, &tol, SolverStatus::Exact);
    let mut scratch = EpaScratch::default();
    let mut counters = QueryCounters::default();
    // Cold: a fresh cache.
    let mut cache = PairCache::default();
    let g = query_polytopes_cached(
        pos1,
        a,
        pos2,
        b,
        &tol,
        &mut cache,
        &mut scratch,
        &mut counters,
    );
    check_result(
        &format!("{ctx} [cold]"),
        pos1,
        a,
        pos2,
        b,
        &g,
        &oracle,
        stats,
    )?;
    // Warm: the cache of a query at a nearby pose (B moved by 1e-3 of the size and turned by 1e-3 rad), as in
    // a time step of a simulation.
    let scale = a.bounding_radius().max(b.bounding_radius());
    let nudge = Pose::from_parts(
        (Vector::new(0.6, -0.8, 0.3) * 1e-3 * scale).into(),
        crate::math::Rotation::from_scaled_axis(Vector::new(0.3, 0.5, -0.8) * 1e-3),
    );
    let mut cache = PairCache::default();
    let pos2_before = pos2 * nudge;
    query_polytopes_cached(
        pos1,
        a,
        &pos2_before,
        b,
        &tol,
        &mut cache,
        &mut scratch,
        &mut counters,
    );
    let g = query_polytopes_cached(
        pos1,
        a,
        pos2,
        b,
        &tol,
        &mut cache,
        &mut scratch,
        &mut counters,
    );
    stats.warm_starts += counters.epa_warm_starts as usize;
    stats.warm_hits += counters.epa_warm_hits as usize;
    check_result(
        &format!("{ctx} [warm]"),
        pos1,
        a,
        pos2,
        b,
        &g,
        &oracle,
        stats,
    )
}

#[allow(clippy::too_many_arguments)]
fn check_result<A: Polytope, B: Polytope>(
    ctx: &str,
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    g: &ContactGeometry,
    oracle: &ContactGeometry,
    stats: &mut Stats,
) -> Result<(), String> {
    let tol = ContactTolerances::default();
    let scale = a.bounding_radius().max(b.bounding_radius());
    let desc =
        || format!("{ctx}: pos1 = {pos1:?}, pos2 = {pos2:?}\n ours = {g:?}\n sat = {oracle:?}");
    stats.pairs += 1;
    if g.status != SolverStatus::Converged {
        stats.fallbacks += 1;
        if std::env::var("POLYDEM_DEBUG_FALLBACK").is_ok() {
            eprintln!("fallback {:?} kind {:?} {ctx}", g.status, g.kind);
        }
    }
    if g.kind != oracle.kind {
        return Err(format!(
            "wrong kind: {:?} vs exact {:?}\n{}",
            g.kind,
            oracle.kind,
            desc()
        ));
    }
    let (value, exact, signed_exact) = match g.kind {
        ContactKind::Overlap => {
            stats.overlap += 1;
            (g.depth, oracle.depth, oracle.depth)
        }
        ContactKind::Separated => {
            stats.separated += 1;
            (g.distance, oracle.distance, -oracle.distance)
        }
        ContactKind::Touching => {
            stats.touching += 1;
            (0.0, 0.0, 0.0)
        }
    };
    let allowed = 1e-10 * scale + 1e-9 * exact;
    let err = (value - exact).abs();
    stats.max_value_err = stats.max_value_err.max(err / scale);
    if err > allowed {
        return Err(format!(
            "value error {err:e} > {allowed:e} (measured {value:e}, exact {exact:e})\n{}",
            desc()
        ));
    }
    if (g.normal.norm() - 1.0).abs() > 1e-12 {
        return Err(format!(
            "normal not unit: |n| = {}\n{}",
            g.normal.norm(),
            desc()
        ));
    }
    let along = overlap_along_world(pos1, a, pos2, b, &g.normal);
    let nerr = (along - signed_exact).abs();
    stats.max_normal_err = stats.max_normal_err.max(nerr / scale);
    let touch_allow = tol.touching * a.length_scale().max(b.length_scale());
    let allowed_n = allowed
        + if g.kind == ContactKind::Touching {
            touch_allow
        } else {
            0.0
        };
    if nerr > allowed_n {
        return Err(format!(
            "normal not optimal: overlap along it {along:e}, exact {signed_exact:e}, error {nerr:e} > {allowed_n:e}\n{}",
            desc()
        ));
    }
    if g.kind == ContactKind::Overlap && (g.depth - along).abs() > 1e-13 * scale {
        return Err(format!(
            "depth {:e} is not the support distance along the normal {along:e}\n{}",
            g.depth,
            desc()
        ));
    }
    let sa = surface_distance(pos1, a, &g.point_a);
    let sb = surface_distance(pos2, b, &g.point_b);
    let serr = sa.abs().max(sb.abs());
    stats.max_surface_err = stats.max_surface_err.max(serr / scale);
    let allowed_s = allowed + touch_allow;
    if serr > allowed_s {
        return Err(format!(
            "contact points off the surfaces: {sa:e} (A), {sb:e} (B) > {allowed_s:e}\n{}",
            desc()
        ));
    }
    let expect = match g.kind {
        ContactKind::Overlap => g.normal * g.depth,
        ContactKind::Separated => -g.normal * g.distance,
        ContactKind::Touching => g.point_a - g.point_b,
    };
    let perr = ((g.point_a - g.point_b) - expect).norm();
    if perr > 1e-12 * scale {
        return Err(format!("c1 − c2 ≠ δ n: error {perr:e}\n{}", desc()));
    }
    Ok(())
}

/// Translation along unit `u` (from `pos1`'s centre) at which `b` (orientation `rot2`) first touches `a`.
///
/// With B at `pos1.translation + t u`, the overlap along a SAT axis n is s_n(0) − t n·u, and the pair
/// overlaps iff every axis overlaps (the SAT value's sign is exact). At t = 0 both centroids coincide, so all
/// s_n(0) > 0, and first contact is at t* = min over axes with n·u > 0 of s_n(0) / (n·u).
pub(crate) fn touching_offset<A: Polytope, B: Polytope>(
    pos1: &Pose,
    a: &A,
    rot2: &crate::math::Rotation,
    b: &B,
    u: &Vector,
) -> Real {
    let pos2 = Pose::from_parts(pos1.translation, *rot2);
    let mut axes: Vec<Vector> = (0..a.num_faces())
        .map(|i| pos1.rotation * a.face_normal(i))
        .collect();
    axes.extend((0..b.num_faces()).map(|i| -(pos2.rotation * b.face_normal(i))));
    let (va, vb) = (a.vertices(), b.vertices());
    for ea in a.edges() {
        let e1 = pos1.rotation * (va[ea[1] as usize] - va[ea[0] as usize]).normalize();
        for eb in b.edges() {
            let e2 = pos2.rotation * (vb[eb[1] as usize] - vb[eb[0] as usize]).normalize();
            if let Some(n) = sat::edge_edge_axis(&e1, &e2) {
                axes.push(n);
                axes.push(-n);
            }
        }
    }
    axes.iter()
        .filter(|n| n.dot(u) > 1e-9)
        .map(|n| overlap_along_world(pos1, a, &pos2, b, n) / n.dot(u))
        .fold(Real::INFINITY, Real::min)
}

pub(crate) fn random_tetrahedron(rng: &mut impl Rng, size: Real) -> TestPolytope {
    loop {
        let p: [Point; 4] = std::array::from_fn(|_| {
            Point::from(random_unit(rng) * size * rng.random_range(0.5..1.0))
        });
        let vol = (p[1] - p[0])
            .dot(&(p[2] - p[0]).cross(&(p[3] - p[0])))
            .abs()
            / 6.0;
        if vol > 0.02 * size * size * size {
            return TestPolytope::tetrahedron(p);
        }
    }
}

/// Points on an ellipsoid with semi-axes up to 3:1.
fn ellipsoid_points(rng: &mut impl Rng, size: Real, n: usize) -> Vec<Point> {
    let axes = Vector::new(
        1.0,
        rng.random_range(1.0 / 3.0..1.0),
        rng.random_range(1.0 / 3.0..1.0),
    ) * size;
    (0..n)
        .map(|_| Point::from(random_unit(rng).component_mul(&axes)))
        .collect()
}

/// Vertices of a Voronoi-like cell: the cell of the origin among random neighbours at distances
/// 0.8–1.6 `size` (half-spaces x·p ≤ |p|²/2), by brute-force plane triples.
pub(crate) fn voronoi_cell_points(rng: &mut impl Rng, size: Real, neighbours: usize) -> Vec<Point> {
    let mut planes: Vec<(Vector, Real)> = (0..neighbours)
        .map(|_| {
            let p = random_unit(rng) * size * rng.random_range(0.8..1.6);
            (p.normalize(), 0.5 * p.norm())
        })
        .collect();
    for d in [
        Vector::x(),
        -Vector::x(),
        Vector::y(),
        -Vector::y(),
        Vector::z(),
        -Vector::z(),
    ] {
        planes.push((d, 1.5 * size));
    }
    let mut pts = Vec::new();
    let m = planes.len();
    for i in 0..m {
        for j in i + 1..m {
            for k in j + 1..m {
                let mat = crate::math::Matrix::from_rows(&[
                    planes[i].0.transpose(),
                    planes[j].0.transpose(),
                    planes[k].0.transpose(),
                ]);
                let Some(inv) = mat.try_inverse() else {
                    continue;
                };
                if mat.determinant().abs() < 1e-6 {
                    continue;
                }
                let x = inv * Vector::new(planes[i].1, planes[j].1, planes[k].1);
                if planes.iter().all(|(n, o)| n.dot(&x) <= o + 1e-9 * size) {
                    pts.push(Point::from(x));
                }
            }
        }
    }
    pts
}

/// Shape classes of the random sets, all built by the production constructor.
pub(crate) const CLASS_NAMES: [&str; 10] = [
    "tetrahedron",
    "box",
    "hull8",
    "hull16",
    "hull32",
    "hull64",
    "voronoi",
    "box-exact",
    "plate",
    "needle",
];

pub(crate) fn random_polyhedron(rng: &mut impl Rng, size: Real, class: usize) -> ConvexPolyhedron {
    let pts: Vec<Point> = match class {
        0 => random_tetrahedron(rng, size).verts,
        1 | 7 => random_box(rng, size).verts,
        2 => ellipsoid_points(rng, size, 8),
        3 => ellipsoid_points(rng, size, 16),
        4 => ellipsoid_points(rng, size, 32),
        5 => ellipsoid_points(rng, size, 64),
        8 => {
            TestPolytope::cuboid(
                Vector::new(
                    1.0,
                    rng.random_range(0.5..1.0),
                    rng.random_range(0.005..0.02),
                ) * size,
            )
            .verts
        }
        9 => {
            let axes = Vector::new(
                1.0,
                rng.random_range(0.02..0.08),
                rng.random_range(0.02..0.08),
            ) * size;
            (0..16)
                .map(|_| Point::from(random_unit(rng).component_mul(&axes)))
                .collect()
        }
        _ => voronoi_cell_points(rng, size, 24),
    };
    ConvexPolyhedron::from_points(&pts)
        .expect("valid random shape")
        .0
}

pub(crate) fn random_box(rng: &mut impl Rng, size: Real) -> TestPolytope {
    TestPolytope::cuboid(Vector::new(
        rng.random_range(0.3..1.0) * size,
        rng.random_range(0.3..1.0) * size,
        rng.random_range(0.3..1.0) * size,
    ))
}

/// Runs `count` random pairs of class pair (ca, cb) at `size`; returns the stats or the first failure.
fn random_pairs(seed: u64, count: usize, size: Real, classes: &[(usize, usize)]) -> Stats {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut stats = Stats::default();
    let mut failures = Vec::new();
    for i in 0..count {
        let (ca, cb) = classes[i % classes.len()];
        let a = random_polyhedron(&mut rng, size, ca);
        let b = random_polyhedron(&mut rng, size, cb);
        let pos1 = random_pose(&mut rng, size);
        let rot2 = random_rotation(&mut rng);
        let u = random_unit(&mut rng);
        let t0 = touching_offset(&pos1, &a, &rot2, &b, &u);
        // 0..5: overlaps log-spread over 1e-9..0.3 of the size; 6: touching; 7: separated (log-spread).
        // Every class pair meets every mode.
        let mode = (i / classes.len()) % 8;
        let x = size * 10f64.powf(rng.random_range(-9.0..(0.3f64).log10()));
        let t = match mode {
            6 => t0,
            7 => t0 + x,
            _ => t0 - x,
        };
        let pos2 = Pose::from_parts((pos1.translation.vector + u * t).into(), rot2);
        let ctx = format!(
            "seed {seed} pair {i} classes ({},{})",
            CLASS_NAMES[ca], CLASS_NAMES[cb]
        );
        let ctx = format!("{ctx} size {size:e} mode {mode} offset {x:e}");
        if let Err(e) = check_pair(&ctx, &pos1, &a, &pos2, &b, &mut stats) {
            failures.push(e);
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} pairs failed; first ones:\n{}",
        failures.len(),
        count,
        failures
            .iter()
            .take(3)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n\n")
    );
    stats
}

const CLASSES: [(usize, usize); 21] = [
    (0, 0),
    (1, 1),
    (2, 2),
    (3, 3),
    (4, 4),
    (5, 5),
    (6, 6),
    (0, 1),
    (0, 6),
    (1, 4),
    (2, 5),
    (3, 6),
    (4, 6),
    (5, 1),
    (6, 2),
    (4, 0),
    (8, 8),
    (9, 9),
    (8, 1),
    (9, 6),
    (8, 9),
];

#[test]
fn random_pairs_match_sat_at_unit_size() {
    let s = random_pairs(1, 1344, 1.0, &CLASSES);
    println!("{s:?}");
}

#[test]
fn random_pairs_match_sat_at_millimetre_size() {
    let s = random_pairs(2, 504, 1e-3, &CLASSES);
    println!("{s:?}");
}

#[test]
fn random_pairs_match_sat_at_kilometre_size() {
    let s = random_pairs(3, 504, 1e3, &CLASSES);
    println!("{s:?}");
}

/// Large sweep for manual runs: `POLYDEM_SWEEP=100000 cargo test --release -- --ignored sweep`.
#[test]
#[ignore]
fn sweep() {
    let n: usize = std::env::var("POLYDEM_SWEEP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    for (seed, size) in [(11u64, 1.0), (12, 1e-3), (13, 1e3)] {
        let s = random_pairs(seed, n, size, &CLASSES);
        println!("{size:e}: {s:?}");
    }
}

/// A solver that hits its cap never reports "no contact": the query falls back to the exact SAT answer,
/// says so in the status and counts it.
#[test]
fn capped_solvers_fall_back_to_the_exact_answer_and_are_counted() {
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let capped = [
        ContactTolerances {
            gjk_max_iterations: 1,
            ..ContactTolerances::default()
        },
        ContactTolerances {
            epa_max_iterations: 0,
            ..ContactTolerances::default()
        },
    ];
    for (k, tol) in capped.iter().enumerate() {
        let mut counters = QueryCounters::default();
        let mut scratch = EpaScratch::new(tol);
        let mut fallbacks = 0;
        for i in 0..200 {
            let a = random_polyhedron(&mut rng, 1.0, 3);
            let b = random_polyhedron(&mut rng, 1.0, 6);
            let pos1 = random_pose(&mut rng, 1.0);
            let rot2 = random_rotation(&mut rng);
            let u = random_unit(&mut rng);
            let t0 = touching_offset(&pos1, &a, &rot2, &b, &u);
            let t = t0 - 0.1 + 0.2 * (i % 2) as Real;
            let pos2 = Pose::from_parts((pos1.translation.vector + u * t).into(), rot2);
            let g = query_polytopes_cached(
                &pos1,
                &a,
                &pos2,
                &b,
                tol,
                &mut PairCache::default(),
                &mut scratch,
                &mut counters,
            );
            let exact = sat_polytopes(&pos1, &a, &pos2, &b, tol, SolverStatus::Exact);
            assert_eq!(
                g.kind, exact.kind,
                "cap set {k}, pair {i}: {g:?} vs {exact:?}"
            );
            let (v, e) = (g.depth + g.distance, exact.depth + exact.distance);
            assert!(
                (v - e).abs() <= 1e-10 + 1e-9 * e,
                "cap set {k}, pair {i}: value {v} vs exact {e}"
            );
            if g.status == SolverStatus::FallbackAfterMaxIterations {
                fallbacks += 1;
            } else {
                assert_eq!(g.status, SolverStatus::Converged, "cap set {k}, pair {i}");
            }
        }
        assert!(
            fallbacks > 50,
            "cap set {k}: only {fallbacks} of 200 queries hit the cap"
        );
        assert_eq!(
            counters.fallback_max_iterations, fallbacks as u64,
            "cap set {k}: {counters}"
        );
    }
}

/// Non-finite input (a NaN or infinite pose) must not panic: the query returns a geometry whose non-finite
/// values the caller's checks catch.
#[test]
fn non_finite_poses_do_not_panic() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let a = random_polyhedron(&mut rng, 1.0, 4);
    let b = random_polyhedron(&mut rng, 1.0, 6);
    let tol = ContactTolerances::default();
    for bad in [Real::NAN, Real::INFINITY, -Real::INFINITY] {
        let pos2 = Pose::translation(bad, 0.1, 0.2);
        let mut counters = QueryCounters::default();
        let g = query_polytopes_cached(
            &Pose::identity(),
            &a,
            &pos2,
            &b,
            &tol,
            &mut PairCache::default(),
            &mut EpaScratch::default(),
            &mut counters,
        );
        let finite =
            g.depth.is_finite() && g.distance.is_finite() && g.normal.iter().all(|x| x.is_finite());
        assert!(
            !finite || g.kind == ContactKind::Separated,
            "translation {bad}: {g:?}"
        );
        let _ = sat_polytopes(&Pose::identity(), &a, &pos2, &b, &tol, SolverStatus::Exact);
    }
}
