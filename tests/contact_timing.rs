//! Quick, criterion-free timing of the contact core against parry3d-f64 on the same seeded pairs, to guide
//! design. Not a gate (no speed assertions): run by hand with
//! `cargo test --release --test contact_timing -- --ignored --nocapture`.
//! The criterion benchmarks of the harness are the reference figures.

use polydem::contact::{
    intersect_polyhedra_cached, query_polyhedra_cached, ContactKind, EpaScratch, PairCache,
    QueryCounters,
};
use polydem::math::glam::{point_to_glam, pose_to_glam};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::ConvexPolyhedron;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::time::Instant;

fn unit(rng: &mut impl Rng) -> Vector {
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

fn rotation(rng: &mut impl Rng) -> Rotation {
    Rotation::from_scaled_axis(unit(rng) * rng.random_range(0.0..std::f64::consts::PI))
}

fn ellipsoid_hull(rng: &mut impl Rng, n: usize) -> Vec<Point> {
    let axes = Vector::new(
        1.0,
        rng.random_range(1.0 / 3.0..1.0),
        rng.random_range(1.0 / 3.0..1.0),
    );
    (0..n)
        .map(|_| Point::from(unit(rng).component_mul(&axes)))
        .collect()
}

fn voronoi_cell(rng: &mut impl Rng) -> Vec<Point> {
    let mut planes: Vec<(Vector, Real)> = (0..24)
        .map(|_| {
            let p = unit(rng) * rng.random_range(0.8..1.6);
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
        planes.push((d, 1.5));
    }
    let mut pts = Vec::new();
    for i in 0..planes.len() {
        for j in i + 1..planes.len() {
            for k in j + 1..planes.len() {
                let m = polydem::math::Matrix::from_rows(&[
                    planes[i].0.transpose(),
                    planes[j].0.transpose(),
                    planes[k].0.transpose(),
                ]);
                if m.determinant().abs() < 1e-6 {
                    continue;
                }
                let x = m.try_inverse().expect("invertible")
                    * Vector::new(planes[i].1, planes[j].1, planes[k].1);
                if planes.iter().all(|(n, o)| n.dot(&x) <= o + 1e-9) {
                    pts.push(Point::from(x));
                }
            }
        }
    }
    pts
}

struct PairSet {
    ours: Vec<(ConvexPolyhedron, ConvexPolyhedron)>,
    parry: Vec<(
        parry3d_f64::shape::ConvexPolyhedron,
        parry3d_f64::shape::ConvexPolyhedron,
    )>,
    overlapping: Vec<(usize, Pose, Pose)>,
    separated: Vec<(usize, Pose, Pose)>,
}

fn pair_set(seed: u64, class: &str, shapes: usize, poses: usize) -> PairSet {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut set = PairSet {
        ours: vec![],
        parry: vec![],
        overlapping: vec![],
        separated: vec![],
    };
    for _ in 0..shapes {
        let make = |rng: &mut ChaCha8Rng| {
            let pts = match class {
                "hull16" => ellipsoid_hull(rng, 16),
                "hull32" => ellipsoid_hull(rng, 32),
                _ => voronoi_cell(rng),
            };
            let (shape, _) = ConvexPolyhedron::from_points(&pts).expect("shape");
            // parry gets exactly our (principal-frame) vertices.
            let v: Vec<_> = shape.vertices().iter().map(point_to_glam).collect();
            let ps =
                parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&v).expect("parry hull");
            (shape, ps)
        };
        let (a, pa) = make(&mut rng);
        let (b, pb) = make(&mut rng);
        set.ours.push((a, b));
        set.parry.push((pa, pb));
    }
    let mut scratch = EpaScratch::default();
    let mut counters = QueryCounters::default();
    while set.overlapping.len() < poses || set.separated.len() < poses {
        let i = rng.random_range(0..shapes);
        let (a, b) = &set.ours[i];
        let r = a.bounding_radius() + b.bounding_radius();
        let pos1 = Pose::from_parts(Vector::zeros().into(), rotation(&mut rng));
        let t = unit(&mut rng) * r * rng.random_range(0.3..1.0);
        let pos2 = Pose::from_parts(t.into(), rotation(&mut rng));
        let g = query_polyhedra_cached(
            &pos1,
            a,
            &pos2,
            b,
            &mut PairCache::default(),
            &mut scratch,
            &mut counters,
        );
        match g.kind {
            ContactKind::Overlap if set.overlapping.len() < poses => {
                set.overlapping.push((i, pos1, pos2))
            }
            ContactKind::Separated if set.separated.len() < poses => {
                set.separated.push((i, pos1, pos2))
            }
            _ => {}
        }
    }
    set
}

/// The fastest of `reps` runs of `f` (each doing `n` queries), in ns per query: the minimum is robust to
/// interference from other processes on a shared machine.
fn min_ns(reps: usize, n: usize, mut f: impl FnMut()) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_nanos() as f64 / n as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// [`min_ns`] of one pass of `query` over `pairs` (shape-pair index, pose of A, pose of B; `k` is the
/// position in `pairs`, for per-pair caches).
fn time_pairs(
    reps: usize,
    pairs: &[(usize, Pose, Pose)],
    mut query: impl FnMut(usize, usize, &Pose, &Pose),
) -> f64 {
    min_ns(reps, pairs.len(), || {
        for (k, (i, p1, p2)) in pairs.iter().enumerate() {
            query(k, *i, p1, p2);
        }
    })
}

#[test]
#[ignore]
fn timing_against_parry() {
    for class in ["hull16", "hull32", "voronoi"] {
        let set = pair_set(42, class, 50, 2000);
        let reps = 9;
        let mut scratch = EpaScratch::default();
        let mut counters = QueryCounters::default();
        // Overlapping, cold cache.
        let ours_cold = time_pairs(reps, &set.overlapping, |_, i, p1, p2| {
            let (a, b) = &set.ours[i];
            let mut cache = PairCache::default();
            black_box(query_polyhedra_cached(
                p1,
                a,
                p2,
                b,
                &mut cache,
                &mut scratch,
                &mut counters,
            ));
        });
        // Overlapping, warm cache (the pair's cache from the previous query of the same pair).
        let mut caches = vec![PairCache::default(); set.overlapping.len()];
        time_pairs(1, &set.overlapping, |k, i, p1, p2| {
            let (a, b) = &set.ours[i];
            query_polyhedra_cached(p1, a, p2, b, &mut caches[k], &mut scratch, &mut counters);
        });
        let ours_warm = time_pairs(reps, &set.overlapping, |k, i, p1, p2| {
            let (a, b) = &set.ours[i];
            black_box(query_polyhedra_cached(
                p1,
                a,
                p2,
                b,
                &mut caches[k],
                &mut scratch,
                &mut counters,
            ));
        });
        let parry = time_pairs(reps, &set.overlapping, |_, i, p1, p2| {
            let (a, b) = &set.parry[i];
            black_box(
                parry3d_f64::query::contact(&pose_to_glam(p1), a, &pose_to_glam(p2), b, 0.0).ok(),
            );
        });
        println!(
            "{class} overlapping: ours cold {ours_cold:.0} ns, warm {ours_warm:.0} ns, parry contact {parry:.0} ns, ratio cold/parry {:.2}",
            ours_cold / parry
        );
        // Separated: boolean rejection and full query.
        let rej_cold = time_pairs(reps, &set.separated, |_, i, p1, p2| {
            let (a, b) = &set.ours[i];
            black_box(intersect_polyhedra_cached(
                p1,
                a,
                p2,
                b,
                &mut PairCache::default(),
                &mut counters,
            ));
        });
        let mut caches = vec![PairCache::default(); set.separated.len()];
        time_pairs(1, &set.separated, |k, i, p1, p2| {
            let (a, b) = &set.ours[i];
            intersect_polyhedra_cached(p1, a, p2, b, &mut caches[k], &mut counters);
        });
        let rej_warm = time_pairs(reps, &set.separated, |k, i, p1, p2| {
            let (a, b) = &set.ours[i];
            black_box(intersect_polyhedra_cached(
                p1,
                a,
                p2,
                b,
                &mut caches[k],
                &mut counters,
            ));
        });
        let full_sep = time_pairs(reps, &set.separated, |_, i, p1, p2| {
            let (a, b) = &set.ours[i];
            let mut cache = PairCache::default();
            black_box(query_polyhedra_cached(
                p1,
                a,
                p2,
                b,
                &mut cache,
                &mut scratch,
                &mut counters,
            ));
        });
        let parry_sep = time_pairs(reps, &set.separated, |_, i, p1, p2| {
            let (a, b) = &set.parry[i];
            black_box(
                parry3d_f64::query::intersection_test(&pose_to_glam(p1), a, &pose_to_glam(p2), b)
                    .ok(),
            );
        });
        println!(
            "{class} separated: ours reject cold {rej_cold:.0} ns, warm {rej_warm:.0} ns, full query cold {full_sep:.0} ns; parry intersection_test {parry_sep:.0} ns; ratio cold/parry {:.2}, warm/parry {:.2}",
            rej_cold / parry_sep,
            rej_warm / parry_sep
        );
        println!("{counters}");
    }
}

#[inline(never)]
fn ir_ours_overlap(set: &PairSet, scratch: &mut EpaScratch, counters: &mut QueryCounters) {
    for (i, p1, p2) in &set.overlapping {
        let (a, b) = &set.ours[*i];
        black_box(query_polyhedra_cached(
            p1,
            a,
            p2,
            b,
            &mut PairCache::default(),
            scratch,
            counters,
        ));
    }
}

#[inline(never)]
fn ir_parry_overlap(set: &PairSet) {
    for (i, p1, p2) in &set.overlapping {
        let (a, b) = &set.parry[*i];
        black_box(
            parry3d_f64::query::contact(&pose_to_glam(p1), a, &pose_to_glam(p2), b, 0.0).ok(),
        );
    }
}

#[inline(never)]
fn ir_ours_separated(set: &PairSet, counters: &mut QueryCounters) {
    for (i, p1, p2) in &set.separated {
        let (a, b) = &set.ours[*i];
        black_box(intersect_polyhedra_cached(
            p1,
            a,
            p2,
            b,
            &mut PairCache::default(),
            counters,
        ));
    }
}

#[inline(never)]
fn ir_parry_separated(set: &PairSet) {
    for (i, p1, p2) in &set.separated {
        let (a, b) = &set.parry[*i];
        black_box(
            parry3d_f64::query::intersection_test(&pose_to_glam(p1), a, &pose_to_glam(p2), b).ok(),
        );
    }
}

/// A fixed workload for instruction counting (no timing): each `ir_*` function runs one pass over the
/// class's pairs, so that `callgrind_annotate --inclusive=yes` gives instructions per query (divide by the
/// pair count printed here). Run by hand under
/// `valgrind --tool=callgrind <test binary> --ignored --exact callgrind_workload`.
#[test]
#[ignore]
fn callgrind_workload() {
    let class = std::env::var("POLYDEM_IR_CLASS").unwrap_or_else(|_| "hull16".into());
    let set = pair_set(42, &class, 50, 300);
    let mut scratch = EpaScratch::default();
    let mut counters = QueryCounters::default();
    ir_ours_overlap(&set, &mut scratch, &mut counters);
    ir_parry_overlap(&set);
    ir_ours_separated(&set, &mut counters);
    ir_parry_separated(&set);
    println!(
        "{class}: {} overlapping, {} separated pairs",
        set.overlapping.len(),
        set.separated.len()
    );
}
