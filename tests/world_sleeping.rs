//! Sleeping (`polydem::world::sleeping`) on a settled bed struck by a projectile.
//!
//! A bed of 128 spheres (two layers of 8 × 8 on a square lattice, μ = 0.5, e = 0.3) settles under gravity
//! with a global viscous damping, which is then removed. (Polyhedral beds were tried first: within the few
//! thousand steps a test can afford, 3-layer and 2-layer beds of random hulls kept a median speed of 10–40
//! times the rest speed, with damping at 5–30 /s; the single contact point per face lets resting polyhedra
//! rock, a known problem in the README. A disordered sphere bed keeps rolling for the same reason of budget.) A steel sphere (radius 0.05 m, 5 m/s downwards) starts above the
//! bed so that it arrives after ~500 steps, and the run continues while it ploughs into the bed. With
//! sleeping on, the bed falls asleep before the impact and the projectile's island wakes when it touches it.
//! - The projectile's velocity at the end agrees with the run without sleeping within 0.5 %.
//! - Sleeping evaluates fewer contact candidates over the run.
//! - The run with sleeping is bit-identical for 1 and 2 threads.
//! - While the bed sleeps, the floor carries its weight (the frozen contacts keep their forces).
//!
//! Local waking, on a column of 40 spheres standing on the floor (every contact carries the weight above it,
//! so the column is one connected group in which every body touches the next), struck on top by a steel
//! sphere, from an exact equilibrium, with every sphere put to sleep after the first step:
//! - the wake front: each sphere wakes within one pulse travel time per sphere of the step at which, in the
//!   run without sleeping, its load first departs from equilibrium by the wake threshold; the woken spheres
//!   are always a top segment of the column; the striker's velocity agrees with the run without sleeping
//!   within 0.5 %;
//! - the far part of the column, which the pulse has not reached, stays asleep and exactly in place (the
//!   run without sleeping moves it by less than 1e-9 of a diameter), although it touches the woken part.

#[path = "support/bed.rs"]
mod bed;

use polydem::dynamics::{PrincipalInertia, RigidBody, ViscousDamping};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Vector};
use polydem::shape::{Plane, Shape, Sphere};
use polydem::world::{
    sleeping, step, MaterialTable, Parallelism, SleepParams, StepCounters, StepParams, StepScratch,
    Wall, World,
};

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
            .bodies()
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != p)
            .map(|(_, body)| body.mass * 9.81)
            .sum();
        for _ in 0..STEPS {
            let r = step(&b.params, &mut b.world, &mut scratch).expect("step");
            counters.merge(&r.counters);
            max_sleeping = max_sleeping.max(b.world.sleep().asleep_count());
            if b.world.sleep().asleep_count() == b.world.bodies().len() - 1
                && floor_while_asleep.is_none()
            {
                floor_while_asleep = Some((-b.world.loads().wall_forces()[0].z, weight));
            }
        }
        Outcome {
            velocity: b.world.bodies()[p].velocity,
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
    let bodies = 129.0;
    eprintln!(
        "projectile velocity without sleeping {:?}, with {:?}: relative difference {dv:e}; candidates evaluated \
         {e_awake} vs {e_asleep} ({:.1} %), body-steps asleep {:.1} %, frozen {}, bodies asleep at most {}, \
         fell asleep {}, woken {}",
        awake.velocity,
        asleep.velocity,
        100.0 * e_asleep as f64 / e_awake as f64,
        100.0 * asleep.counters.sleeping_body_steps as f64 / (bodies * STEPS as f64),
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

/// Spheres of the column (the striker is one more body).
const COLUMN: usize = 40;
const RADIUS: Real = 0.05;
const STIFFNESS: Real = 1.0e6;
const DENSITY: Real = 2600.0;

/// The column of [`COLUMN`] spheres on the floor in exact equilibrium (each linear contact compressed by the
/// weight above it), a steel striker of the same radius 0.2 diameters above the top, falling at 1 m/s; the
/// step parameters; the striker's index.
fn column() -> (World, StepParams, usize) {
    let mut materials = MaterialTable::default();
    let rock = materials.add_material("rock");
    let model = ContactModel {
        normal: NormalLaw::linear(STIFFNESS).expect("stiffness"),
        damping: DampingLaw::from_restitution(1.0, 0.5).expect("restitution"),
        tangential: TangentialLaw::spring(0.5 * STIFFNESS, 0.5).expect("spring"),
    };
    materials.set_model(rock, rock, model);
    let g = 9.81;
    let mut world = World::new(Vector::new(0.0, 0.0, -g), materials, 0.05 * 2.0 * RADIUS);
    let sphere = Sphere::new(RADIUS).expect("sphere");
    let props = sphere.mass_properties();
    let shape = world.add_shape(Shape::Sphere(sphere));
    let mass = props.volume * DENSITY;
    let inertia = PrincipalInertia::new(props.principal_moments * DENSITY).expect("inertia");
    // Contact j (0 = the floor) carries the weight of the spheres j.. above it: overlap (N − j) m g / k.
    let overlap = |j: usize| (COLUMN - j) as Real * mass * g / STIFFNESS;
    let mut z = RADIUS - overlap(0);
    for j in 0..COLUMN {
        if j > 0 {
            z += 2.0 * RADIUS - overlap(j);
        }
        let body = RigidBody::new_dynamic(Point::new(0.0, 0.0, z), mass, inertia).expect("body");
        world
            .add_body(&format!("s{j}"), shape, rock, body)
            .expect("body added");
    }
    world
        .add_wall(Wall {
            name: "floor".to_owned(),
            plane: Plane::new(Vector::z(), 0.0).expect("plane"),
            pose: Pose::identity(),
            velocity: Vector::zeros(),
            material: rock,
        })
        .expect("floor");
    let steel = 7800.0;
    let mut striker = RigidBody::new_dynamic(
        Point::new(0.0, 0.0, z + 2.0 * RADIUS + 0.2 * 2.0 * RADIUS),
        props.volume * steel,
        PrincipalInertia::new(props.principal_moments * steel).expect("inertia"),
    )
    .expect("striker");
    striker.velocity = Vector::new(0.0, 0.0, -1.0);
    let p = world
        .add_body("striker", shape, rock, striker)
        .expect("striker added") as usize;
    let t_c = model.normal.elastic_contact_time(0.5 * mass, 1.0);
    let mut params = StepParams::new(t_c / 40.0);
    params.parallel = Parallelism {
        min_candidates: 0,
        min_bodies: 0,
    };
    (world, params, p)
}

struct ColumnRun {
    /// Per sphere: the first step at which it was awake (sleeping) or its load departed from equilibrium by
    /// the wake threshold (without sleeping); `None` if never.
    first: Vec<Option<usize>>,
    /// Per step: the woken spheres form a top segment of the column.
    top_segment: bool,
    positions: Vec<Point>,
    striker_velocity: Vector,
    sleeping_body_steps: u64,
}

/// Runs the struck column for one step and then `steps` steps, all spheres asleep after the first step when
/// `sleeping`.
fn strike_column(sleeping: bool, steps: usize) -> ColumnRun {
    let (mut world, mut params, p) = column();
    let sleep = SleepParams::on();
    let mut scratch = StepScratch::default();
    // One step awake in both runs, so that the contacts have been evaluated (their forces are what the
    // sleeping spheres keep).
    step(&params, &mut world, &mut scratch).expect("first step");
    if sleeping {
        params.sleeping = sleep;
        let n = sleeping::put_to_sleep(&sleep, &mut world, 0..COLUMN);
        assert_eq!(n, COLUMN, "every sphere of the column falls asleep");
    }
    let g = world.gravity().norm();
    let mut first = vec![None; COLUMN];
    let mut top_segment = true;
    let mut counters = StepCounters::default();
    for s in 0..steps {
        let r = step(&params, &mut world, &mut scratch).expect("step");
        counters.merge(&r.counters);
        for (j, f) in first.iter_mut().enumerate() {
            let body = &world.bodies()[j];
            let disturbed = if sleeping {
                !world.sleep().is_asleep(j)
            } else {
                let net = world.loads().forces()[j] + body.mass * world.gravity();
                net.norm() > sleep.rest_force * body.mass * g
                    || world.loads().torques()[j].norm() > sleep.rest_force * body.mass * g * RADIUS
            };
            if disturbed && f.is_none() {
                *f = Some(s);
            }
        }
        if sleeping {
            // Awake spheres (index from the floor up) must be a top segment: no sleeping sphere above one
            // that woke.
            let lowest_awake = (0..COLUMN).find(|&j| !world.sleep().is_asleep(j));
            if let Some(low) = lowest_awake {
                top_segment &= (low..COLUMN).all(|j| !world.sleep().is_asleep(j));
            }
        }
    }
    ColumnRun {
        first,
        top_segment,
        positions: world.bodies().iter().map(|b| b.position).collect(),
        striker_velocity: world.bodies()[p].velocity,
        sleeping_body_steps: counters.sleeping_body_steps,
    }
}

/// Steps of the column runs: the pulse crosses about half of the column.
const COLUMN_STEPS: usize = 500;

/// Steps for a pulse to cross one sphere: 2 r / c with the chain's wave speed c = 2 r √(k/m).
fn steps_per_sphere(params: &StepParams) -> Real {
    let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    1.0 / (STIFFNESS / mass).sqrt() / params.dt
}

#[test]
fn wake_front_follows_the_pulse_down_a_sleeping_column() {
    let awake = strike_column(false, COLUMN_STEPS);
    let asleep = strike_column(true, COLUMN_STEPS);
    let (_, params, _) = column();
    let tolerance = steps_per_sphere(&params);
    eprintln!(
        "arrival step per sphere (top first) without sleeping {:?}\nwake step with sleeping {:?}\n\
         tolerance {tolerance:.1} steps (one sphere's pulse travel time); sphere-steps asleep {:.1} %",
        awake.first.iter().rev().collect::<Vec<_>>(),
        asleep.first.iter().rev().collect::<Vec<_>>(),
        100.0 * asleep.sleeping_body_steps as f64 / ((COLUMN + 1) * COLUMN_STEPS) as f64
    );
    let reached = awake.first.iter().filter(|f| f.is_some()).count();
    assert!(
        (5..COLUMN - 5).contains(&reached),
        "the pulse reached {reached} of {COLUMN} spheres in {COLUMN_STEPS} steps: the test needs a front \
         inside the column"
    );
    assert!(
        asleep.top_segment,
        "the woken spheres were not always a top segment of the column"
    );
    for j in 0..COLUMN {
        match (awake.first[j], asleep.first[j]) {
            (Some(a), Some(b)) => assert!(
                (a as Real - b as Real).abs() <= tolerance,
                "sphere {j}: load departs from equilibrium at step {a} without sleeping, woken at step {b} \
                 with sleeping; tolerance {tolerance:.1} steps"
            ),
            (None, None) => {}
            (a, b) => {
                // Only at the edge of the front may one run see the disturbance and the other not.
                let last = a.or(b).expect("one of them");
                assert!(
                    (COLUMN_STEPS - 1 - last) as Real <= tolerance,
                    "sphere {j}: disturbed at {a:?} without sleeping, woken at {b:?} with sleeping"
                );
            }
        }
    }
    let dv = (asleep.striker_velocity - awake.striker_velocity).norm()
        / awake.striker_velocity.norm().max(1.0);
    assert!(
        dv <= 5e-3,
        "striker velocity with sleeping {:?}, without {:?}: relative difference {dv:e} (of max(|v|, 1 m/s)), \
         tolerance 5e-3",
        asleep.striker_velocity,
        awake.striker_velocity
    );
}

#[test]
fn far_part_of_a_touching_column_stays_asleep_and_in_place() {
    let awake = strike_column(false, COLUMN_STEPS);
    let asleep = strike_column(true, COLUMN_STEPS);
    let (world, _, _) = column();
    let diameter = 2.0 * RADIUS;
    // The far part: spheres the pulse did not reach without sleeping, less a margin of five spheres.
    let reached_lowest = (0..COLUMN)
        .find(|&j| awake.first[j].is_some())
        .expect("the pulse reached some sphere");
    let far = reached_lowest.saturating_sub(5);
    assert!(
        far >= 10,
        "only {far} spheres far from the front: the test needs a far part"
    );
    for j in 0..far {
        let moved_awake = (awake.positions[j] - world.bodies()[j].position).norm();
        assert!(
            moved_awake <= 1e-9 * diameter,
            "sphere {j} moved {moved_awake:e} m without sleeping: the far part is not at rest (tolerance 1e-9 \
             of the diameter {diameter} m)"
        );
        assert_eq!(
            asleep.first[j], None,
            "sphere {j} (far from the struck top, below sphere {reached_lowest} where the pulse ended) woke"
        );
        assert_eq!(
            asleep.positions[j],
            world.bodies()[j].position,
            "sleeping sphere {j} moved"
        );
    }
}
