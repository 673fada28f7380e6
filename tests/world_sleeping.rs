//! Sleeping (`polydem::world::sleeping`) on a settled bed struck by a projectile.
//!
//! A bed of 128 spheres (two layers of 8 × 8 on a square lattice, μ = 0.5, e = 0.3) settles under gravity
//! with a global viscous damping, which is then removed. (Polyhedral beds were tried first: within the few
//! thousand steps a test can afford, 3-layer and 2-layer beds of random hulls kept a median speed of 10–40
//! times the rest speed, with damping at 5–30 /s; the single contact point per face lets resting polyhedra
//! rock, a known problem in the README. A disordered sphere bed keeps rolling for the same reason of budget.) A steel sphere (radius 0.05 m, 5 m/s downwards) starts above the
//! bed so that it arrives after ~500 steps, and the run continues while it ploughs into the bed. With
//! sleeping on, the bed falls asleep before the impact and the projectile's island wakes when it touches it.
//! - The projectile's velocity at the end agrees with the run without sleeping within 0.5 % (issue 4).
//! - Sleeping evaluates fewer contact candidates over the run.
//! - The run with sleeping is bit-identical for 1 and 2 threads.
//! - While the bed sleeps, the floor carries its weight (the frozen contacts keep their forces).

#[path = "support/bed.rs"]
mod bed;

use polydem::dynamics::ViscousDamping;
use polydem::math::Real;
use polydem::world::{step, Parallelism, SleepParams, StepCounters, StepScratch};

/// The bed after settling (damping removed), with the projectile added; returns it with the projectile's
/// index.
fn struck_bed() -> (bed::Bed, usize) {
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 0.0,
        ..bed::BedSpec::rocks([8, 8, 2], 1, 11)
    };
    let mut b = bed::build(&spec);
    b.params.damping = ViscousDamping::MassProportional(10.0);
    let mut scratch = StepScratch::default();
    for _ in 0..2000 {
        step(&b.params, &mut b.world, &mut scratch).expect("settling step");
    }
    b.params.damping = ViscousDamping::None;
    let speed = 5.0;
    // Arrives after ~500 steps.
    let height = 500.0 * b.params.dt * speed;
    let p = bed::add_projectile(&mut b, 0.05, 7800.0, height, speed);
    (b, p)
}

struct Outcome {
    velocity: polydem::math::Vector,
    counters: StepCounters,
    max_sleeping: usize,
    floor_while_asleep: Option<(Real, Real)>,
}

const STEPS: usize = 1100;

fn strike(sleeping: bool, threads: usize) -> Outcome {
    let (mut b, p) = struck_bed();
    if sleeping {
        b.params.sleeping = SleepParams::on();
    }
    b.params.parallel = Parallelism {
        min_candidates: 0,
        min_bodies: 0,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        let mut scratch = StepScratch::default();
        let mut counters = StepCounters::default();
        let mut max_sleeping = 0;
        let mut floor_while_asleep = None;
        let weight: Real = b
            .world
            .bodies
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != p)
            .map(|(_, body)| body.mass * 9.81)
            .sum();
        for _ in 0..STEPS {
            let r = step(&b.params, &mut b.world, &mut scratch).expect("step");
            counters.merge(&r.counters);
            max_sleeping = max_sleeping.max(b.world.sleep.sleeping);
            if b.world.sleep.sleeping == b.world.bodies.len() - 1 && floor_while_asleep.is_none() {
                floor_while_asleep = Some((-b.world.loads.wall_forces[0].z, weight));
            }
        }
        Outcome {
            velocity: b.world.bodies[p].velocity,
            counters,
            max_sleeping,
            floor_while_asleep,
        }
    })
}

#[test]
fn projectile_residual_velocity_with_and_without_sleeping_agrees_and_sleeping_saves_work() {
    let awake = strike(false, 1);
    let asleep = strike(true, 1);
    let evaluated = |c: &StepCounters| c.body_pairs_tested + c.wall_pairs_tested - c.frozen_pairs;
    let (e_awake, e_asleep) = (evaluated(&awake.counters), evaluated(&asleep.counters));
    let dv = (asleep.velocity - awake.velocity).norm() / awake.velocity.norm();
    eprintln!(
        "projectile velocity without sleeping {:?}, with {:?}: relative difference {dv:e}; candidates evaluated \
         {e_awake} vs {e_asleep} ({:.1} %), frozen {}, bodies asleep at most {}, fell asleep {}, woken {}",
        awake.velocity,
        asleep.velocity,
        100.0 * e_asleep as f64 / e_awake as f64,
        asleep.counters.frozen_pairs,
        asleep.max_sleeping,
        asleep.counters.fell_asleep,
        asleep.counters.woken
    );
    // The projectile must have been slowed by the bed for the comparison to mean anything.
    assert!(
        awake.velocity.z > -4.5 && awake.velocity.z < -0.5,
        "projectile vertical velocity at the end {} m/s: expected slowed from -5 but still moving",
        awake.velocity.z
    );
    assert!(
        asleep.max_sleeping >= 100,
        "the bed never fell asleep: at most {} of 128 bodies asleep",
        asleep.max_sleeping
    );
    assert!(
        asleep.counters.woken > 0,
        "the projectile did not wake the bed"
    );
    assert!(
        dv <= 5e-3,
        "projectile velocity with sleeping {:?} vs without {:?}: relative difference {dv:e}, tolerance 5e-3",
        asleep.velocity,
        awake.velocity
    );
    assert!(
        e_asleep < e_awake,
        "sleeping evaluated {e_asleep} candidates, without sleeping {e_awake}"
    );
    let (floor, weight) = asleep
        .floor_while_asleep
        .expect("a step with the whole bed asleep");
    assert!(
        (floor - weight).abs() <= 0.02 * weight,
        "force on the floor under the sleeping bed {floor} N, bed weight {weight} N, tolerance 2 % (the side \
         walls carry part of it through friction)"
    );
}

#[test]
fn sleeping_runs_are_bit_identical_for_one_and_two_threads() {
    let (one, two) = (strike(true, 1), strike(true, 2));
    assert_eq!(
        one.velocity, two.velocity,
        "projectile velocity differs between 1 and 2 threads"
    );
    assert_eq!(
        (
            one.counters.frozen_pairs,
            one.counters.fell_asleep,
            one.counters.woken,
            one.counters.contacts
        ),
        (
            two.counters.frozen_pairs,
            two.counters.fell_asleep,
            two.counters.woken,
            two.counters.contacts
        ),
        "sleeping counters differ between 1 and 2 threads"
    );
}
