//! The parallel step gives bit-identical results for any thread count.
//!
//! A bed of 288 bodies (six random hulls and every fourth body a sphere) in a box of five walls, with
//! friction (μ = 0.5), contact damping (e = 0.3) and gravity, starts with random velocities and spins from a
//! tight lattice and runs 300 steps in rayon thread pools of 1, 2 and 4 threads, with the parallel
//! thresholds at zero so that every stage takes its parallel path. Every body's position, velocity,
//! orientation and angular momentum, the loads, the contact store and the energy ledger must agree bit for
//! bit with the serial run (thresholds at infinity).

#[path = "support/bed.rs"]
mod bed;

use polydem::world::{step, Parallelism, StepScratch, World};

const STEPS: usize = 300;

/// The test bed with every stage on its parallel path (`threads` given) or serial (`None`).
fn bed_for(threads: Option<usize>) -> bed::Bed {
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 2.0,
        ..bed::BedSpec::rocks([6, 6, 8], 4, 20261121)
    };
    let mut bed = bed::build(&spec);
    bed.params.parallel = match threads {
        None => Parallelism {
            min_candidates: usize::MAX,
            min_bodies: usize::MAX,
        },
        Some(_) => Parallelism {
            min_candidates: 0,
            min_bodies: 0,
        },
    };
    bed
}

/// Runs `go` on the calling thread (`None`) or in a rayon pool of `n` threads.
fn on_threads<T: Send>(threads: Option<usize>, go: impl FnOnce() -> T + Send) -> T {
    match threads {
        None => go(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("thread pool")
            .install(go),
    }
}

fn run(threads: Option<usize>) -> (World, u64) {
    let mut bed = bed_for(threads);
    on_threads(threads, move || {
        let mut scratch = StepScratch::default();
        let mut contacts = 0;
        for _ in 0..STEPS {
            let report = step(&bed.params, &mut bed.world, &mut scratch).expect("step");
            contacts += report.contacts as u64;
        }
        (bed.world, contacts)
    })
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn one_two_and_four_threads_give_bit_identical_states() {
    let (serial, serial_contacts) = run(None);
    assert!(
        serial_contacts > 1000,
        "the scene must be contact-rich to test anything: {serial_contacts} contact evaluations in {STEPS} steps"
    );
    let wall_force = serial.loads().wall_forces()[0].z;
    assert!(
        wall_force < 0.0,
        "the floor must be pushed down after {STEPS} steps: force on the floor {wall_force} N (z)"
    );
    for threads in [1, 2, 4] {
        let (w, contacts) = run(Some(threads));
        assert_eq!(
            contacts, serial_contacts,
            "{threads} threads: contact evaluations differ"
        );
        for (i, (a, b)) in serial.bodies().iter().zip(w.bodies()).enumerate() {
            let fields = [
                (
                    "position",
                    bits(a.position.coords.as_slice()),
                    bits(b.position.coords.as_slice()),
                ),
                (
                    "velocity",
                    bits(a.velocity.as_slice()),
                    bits(b.velocity.as_slice()),
                ),
                (
                    "orientation",
                    bits(a.orientation.coords.as_slice()),
                    bits(b.orientation.coords.as_slice()),
                ),
                (
                    "angular momentum",
                    bits(a.angular_momentum.as_slice()),
                    bits(b.angular_momentum.as_slice()),
                ),
            ];
            for (name, x, y) in fields {
                assert_eq!(
                    x, y,
                    "{threads} threads, body {i}: {name} differs from the serial run after {STEPS} steps \
                     (serial {a:?}, parallel {b:?})"
                );
            }
        }
        assert_eq!(serial.loads(), w.loads(), "{threads} threads: loads differ");
        assert_eq!(
            serial.contacts(),
            w.contacts(),
            "{threads} threads: contact stores differ"
        );
        let (ea, eb) = (serial.energy(), w.energy());
        assert_eq!(
            bits(&[
                ea.translational_kinetic,
                ea.rotational_kinetic,
                ea.elastic_potential,
                ea.dissipated_damping,
                ea.dissipated_friction,
                ea.external_work,
                ea.balance
            ]),
            bits(&[
                eb.translational_kinetic,
                eb.rotational_kinetic,
                eb.elastic_potential,
                eb.dissipated_damping,
                eb.dissipated_friction,
                eb.external_work,
                eb.balance
            ]),
            "{threads} threads: energy ledger differs (serial {ea:?}, parallel {eb:?})"
        );
    }
}

/// The checks run fused with the second half kick, body by body on several threads: the error must still
/// name the first non-finite body in body order, whatever the thread count.
#[test]
fn the_first_non_finite_body_is_reported_for_any_thread_count() {
    let run = |threads: Option<usize>| {
        let mut bed = bed_for(threads);
        // Two bodies far apart in body order go bad; the later one in a different chunk of the parallel pass.
        let nan = |b: &mut polydem::dynamics::RigidBody| b.velocity.x = f64::NAN;
        let inf = |b: &mut polydem::dynamics::RigidBody| b.angular_momentum.y = f64::INFINITY;
        bed.world.edit_body(250, nan).expect("body 250");
        bed.world.edit_body(37, inf).expect("body 37");
        on_threads(threads, move || {
            let mut world = bed.world;
            let mut scratch = StepScratch::default();
            step(&bed.params, &mut world, &mut scratch)
        })
    };
    let serial =
        run(None).expect_err("a NaN velocity and an infinite angular momentum must fail the step");
    match &serial {
        polydem::world::StepError::NonFinite { body, .. } => assert_eq!(
            *body, 37,
            "the serial step must report body 37 (the first bad one), got {serial}"
        ),
        other => panic!("expected a non-finite error for body 37, got {other}"),
    }
    for threads in [1, 2, 4] {
        let parallel = run(Some(threads)).expect_err("the parallel step must fail too");
        assert_eq!(
            parallel, serial,
            "{threads} threads: the error differs from the serial step's"
        );
    }
}
