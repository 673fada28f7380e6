//! Cost of building a `ConvexPolyhedron` from a point cloud (hull, coplanar merge, checks, mass properties,
//! principal frame, topology), by cloud size: points on a 3:2:1 ellipsoid (all on the hull) and the 8
//! corners of a box (coplanar merging), seeded.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use polydem::math::{Point, Vector};
use polydem::shape::ConvexPolyhedron;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn ellipsoid_cloud(rng: &mut ChaCha8Rng, n: usize) -> Vec<Point> {
    (0..n)
        .map(|_| {
            let d = Vector::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize();
            Point::from(d.component_mul(&Vector::new(3.0, 2.0, 1.0)))
        })
        .collect()
}

fn bench_hull(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut group = c.benchmark_group("polyhedron_from_points");
    for n in [8usize, 16, 32, 64, 256] {
        let cloud = ellipsoid_cloud(&mut rng, n);
        group.bench_with_input(BenchmarkId::new("ellipsoid", n), &cloud, |b, cloud| {
            b.iter(|| ConvexPolyhedron::from_points(black_box(cloud)).map(|(p, _)| p.num_faces()))
        });
    }
    let mut corners = Vec::new();
    for x in [-0.5, 0.5] {
        for y in [-1.0, 1.0] {
            for z in [-1.5, 1.5] {
                corners.push(Point::new(x, y, z));
            }
        }
    }
    group.bench_with_input(BenchmarkId::new("box", 8), &corners, |b, cloud| {
        b.iter(|| ConvexPolyhedron::from_points(black_box(cloud)).map(|(p, _)| p.num_faces()))
    });
    group.finish();
}

criterion_group!(benches, bench_hull);
criterion_main!(benches);
