//! Support-map cost of `ConvexPolyhedron`: full linear scan against hill-climbing over the vertex graph,
//! by vertex count. Decides `LINEAR_SCAN_MAX_VERTICES`.
//!
//! Inputs: hulls of n points on a 3:2:1 ellipsoid (every point is a hull vertex), seeded. Directions: a pool
//! of 1024 unit vectors; "coherent" walks the pool as a slowly turning sequence with the hint carried from
//! call to call (the GJK/EPA pattern), "random" uses independent directions with the carried hint.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use polydem::math::{Point, Vector};
use polydem::shape::ConvexPolyhedron;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn ellipsoid_hull(rng: &mut ChaCha8Rng, n: usize) -> ConvexPolyhedron {
    let points: Vec<Point> = (0..n)
        .map(|_| {
            let d = Vector::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize();
            Point::from(d.component_mul(&Vector::new(3.0, 2.0, 1.0)))
        })
        .collect();
    ConvexPolyhedron::from_points(&points)
        .expect("ellipsoid hull")
        .0
}

fn directions(rng: &mut ChaCha8Rng, coherent: bool) -> Vec<Vector> {
    let mut dirs = Vec::with_capacity(1024);
    let mut d = Vector::new(1.0, 0.3, -0.2).normalize();
    for _ in 0..1024 {
        let step = if coherent { 0.1 } else { 2.0 };
        let jitter = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        d = (d + jitter * step).normalize();
        dirs.push(d);
    }
    dirs
}

fn bench_support(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    for coherent in [true, false] {
        let dirs = directions(&mut rng, coherent);
        let mut group = c.benchmark_group(if coherent {
            "support_coherent"
        } else {
            "support_random"
        });
        for n in [6usize, 8, 12, 16, 24, 32, 48, 64, 128] {
            let shape = ellipsoid_hull(&mut rng, n);
            let label = shape.vertices().len();
            group.bench_with_input(
                BenchmarkId::new("linear_scan", label),
                &shape,
                |b, shape| {
                    b.iter(|| {
                        let mut acc = 0u32;
                        for d in &dirs {
                            acc = acc.wrapping_add(shape.support_vertex_linear(black_box(d)));
                        }
                        acc
                    })
                },
            );
            group.bench_with_input(BenchmarkId::new("hill_climb", label), &shape, |b, shape| {
                b.iter(|| {
                    let mut hint = 0u32;
                    for d in &dirs {
                        hint = shape.support_vertex_hill_climb(black_box(d), hint);
                    }
                    hint
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench_support);
criterion_main!(benches);
