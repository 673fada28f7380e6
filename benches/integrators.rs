//! Cost of one torque-free rotation update per scheme (the DLM splitting with Cayley or exact sub-rotations,
//! RK4, explicit Euler), and of a whole kick–drift–kick body step. Seeded pool of 1024 bodies with random
//! principal moments, orientations and angular momenta; throughput in body-steps.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use polydem::dynamics::rotation::drift_rotation;
use polydem::dynamics::{
    Integrator, PrincipalInertia, RigidBody, RotationScheme, SubRotation, TranslationParams,
    ViscousDamping,
};
use polydem::math::{Point, Rotation, Vector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

const POOL: usize = 1024;

fn pool() -> Vec<(Rotation, Vector, PrincipalInertia)> {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    (0..POOL)
        .map(|_| {
            let axis = Vector::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
            );
            let momentum = Vector::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let inertia = Vector::new(
                rng.random_range(0.5..1.0),
                rng.random_range(1.0..1.5),
                rng.random_range(1.5..2.0),
            );
            (
                Rotation::from_scaled_axis(axis),
                momentum,
                PrincipalInertia::new(inertia).expect("positive"),
            )
        })
        .collect()
}

fn rotation_drift(c: &mut Criterion) {
    let bodies = pool();
    let mut group = c.benchmark_group("rotation_drift");
    group.throughput(Throughput::Elements(POOL as u64));
    for (name, scheme) in [
        (
            "splitting_cayley",
            RotationScheme::Splitting {
                sub_rotation: SubRotation::Cayley,
            },
        ),
        (
            "splitting_exact",
            RotationScheme::Splitting {
                sub_rotation: SubRotation::Exact,
            },
        ),
        ("runge_kutta4", RotationScheme::RungeKutta4),
        ("explicit_euler", RotationScheme::ExplicitEuler),
    ] {
        group.bench_function(name, |b| {
            let mut state = bodies.clone();
            b.iter(|| {
                for (q, l, inertia) in state.iter_mut() {
                    drift_rotation(scheme, q, l, inertia, black_box(1e-3));
                }
            })
        });
    }
    group.finish();
}

fn body_step(c: &mut Criterion) {
    let bodies: Vec<RigidBody> = pool()
        .into_iter()
        .map(|(q, l, inertia)| {
            let mut body =
                RigidBody::new_dynamic(Point::origin(), 1.0, inertia).expect("unit mass");
            body.orientation = q;
            body.angular_momentum = l;
            body
        })
        .collect();
    let integrator = Integrator {
        translation: TranslationParams {
            gravity: Vector::new(0.0, 0.0, -9.81),
            damping: ViscousDamping::None,
        },
        rotation: RotationScheme::default(),
    };
    let mut group = c.benchmark_group("body_step");
    group.throughput(Throughput::Elements(POOL as u64));
    group.bench_function("kick_drift_kick_splitting_cayley", |b| {
        let mut state = bodies.clone();
        let (force, torque) = (Vector::new(0.1, 0.0, 0.0), Vector::new(0.0, 0.01, 0.0));
        b.iter(|| {
            for body in state.iter_mut() {
                integrator.first_half_kick(body, &force, &torque, black_box(1e-3));
                integrator.drift(body, 1e-3);
                integrator.second_half_kick(body, &force, &torque, 1e-3);
            }
        })
    });
    group.finish();
}

criterion_group!(benches, rotation_drift, body_step);
criterion_main!(benches);
