//! Every skip of the step (`polydem::world::skips`) against the step with it switched off.
//!
//! - Exact skips — no tangential spring for μ = 0, no damping term for a zero damping coefficient, no work
//!   for pairs of two fixed bodies: every dynamic body's state and the energy ledger are bit-identical.
//! - The rotation skip for bodies with zero angular momentum (spheres falling onto a floor, frictionless:
//!   their torque is exactly zero): positions and velocities bit-identical, orientations within 1e-15 (the
//!   quaternion renormalisation the skip leaves out).
//! - The query skips (bounding spheres, cached separating axis) and the Verlet skin change which pairs get a
//!   fresh GJK warm start, so EPA answers may differ at the solver tolerance (~1e-15 of the size), and a
//!   granular bed amplifies such differences (colliding bodies are chaotic). On a mixed bed of 288 bodies
//!   over 300 steps (~7 contact times) the monitored results — every body's position and velocity, the
//!   kinetic energy, the force on the floor — must agree within 1e-12 of the size (position), 1e-12 of the
//!   initial speed scale (velocity), 1e-12 relative (energy, floor force). Measured:
//!   5.9e-16 d, 1.6e-14 v0, 0, 2.7e-15: the tolerance leaves room for the amplification of round-off by
//!   the collisions, and is far below any physical effect.

#[path = "support/bed.rs"]
mod bed;

use polydem::dynamics::Motion;
use polydem::dynamics::RigidBody;
use polydem::law::{ContactModel, DampingLaw, TangentialLaw};
use polydem::math::Vector;
use polydem::world::{step, Skips, StepScratch, World};

const STEPS: usize = 300;

fn spec() -> bed::BedSpec {
    bed::BedSpec {
        gap: 0.0,
        speed: 2.0,
        ..bed::BedSpec::rocks([6, 6, 8], 4, 7)
    }
}

/// Runs `bed` for `STEPS` steps with `skips`; returns the world and the narrow-phase counters of interest
/// (bounding-sphere rejections, cached-axis rejections, GJK runs, broad-phase rebuilds).
fn run(mut bed: bed::Bed, skips: Skips) -> (World, [u64; 4]) {
    bed.params.skips = skips;
    let mut scratch = StepScratch::default();
    let mut c = [0u64; 4];
    for _ in 0..STEPS {
        let r = step(&bed.params, &mut bed.world, &mut scratch).expect("step");
        c[0] += r.counters.query.bounding_sphere_rejections;
        c[1] += r.counters.query.cached_axis_rejections;
        c[2] += r.counters.query.gjk_runs;
        c[3] += r.counters.broad_rebuilds;
    }
    (bed.world, c)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn assert_bodies_bit_identical(label: &str, on: &World, off: &World) {
    for (i, (a, b)) in on.bodies().iter().zip(off.bodies()).enumerate() {
        for (name, x, y) in [
            ("position", a.position.coords, b.position.coords),
            ("velocity", a.velocity, b.velocity),
            ("angular momentum", a.angular_momentum, b.angular_momentum),
        ] {
            assert_eq!(
                bits(x.as_slice()),
                bits(y.as_slice()),
                "{label}: body {i} {name} differs with the skip on ({x:?}) and off ({y:?}) after {STEPS} steps"
            );
        }
    }
}

fn assert_ledger_identical(label: &str, on: &World, off: &World) {
    let (a, b) = (on.energy(), off.energy());
    let terms = |e: &polydem::world::EnergyReport| {
        bits(&[
            e.translational_kinetic,
            e.rotational_kinetic,
            e.elastic_potential,
            e.dissipated_damping,
            e.dissipated_friction,
            e.dissipated_viscous,
        ])
    };
    assert_eq!(
        terms(&a),
        terms(&b),
        "{label}: energy ledger differs (on {a:?}, off {b:?})"
    );
}

fn only(f: impl Fn(&mut Skips)) -> Skips {
    let mut s = Skips::all(true);
    f(&mut s);
    s
}

#[test]
fn frictionless_pairs_without_tangential_history_are_bit_identical() {
    let s = bed::BedSpec {
        friction: 0.0,
        ..spec()
    };
    // A spring with μ = 0 (not TangentialLaw::None): the skip replaces it by None.
    let model = ContactModel {
        tangential: TangentialLaw::spring(0.5 * s.stiffness, 0.0).expect("spring"),
        ..bed::model_of(&s)
    };
    let build = || {
        let mut b = bed::build(&s);
        let mut laws = b.world.materials().clone();
        laws.set_model(0, 0, model);
        b.world.set_materials(laws).expect("the same materials");
        b
    };
    let (on, _) = run(build(), Skips::all(true));
    let (off, _) = run(build(), only(|k| k.frictionless_history = false));
    assert!(
        on.contacts()
            .states()
            .iter()
            .filter(|c| c.is_active())
            .count()
            > 20,
        "too few contacts to test anything"
    );
    assert_bodies_bit_identical("μ = 0", &on, &off);
    assert_ledger_identical("μ = 0", &on, &off);
}

#[test]
fn zero_damping_coefficient_skipped_is_bit_identical() {
    let s = spec();
    let model = ContactModel {
        damping: DampingLaw::Viscous { coefficient: 0.0 },
        ..bed::model_of(&s)
    };
    let build = || {
        let mut b = bed::build(&s);
        let mut laws = b.world.materials().clone();
        laws.set_model(0, 0, model);
        b.world.set_materials(laws).expect("the same materials");
        b
    };
    let (on, _) = run(build(), Skips::all(true));
    let (off, _) = run(build(), only(|k| k.undamped_contacts = false));
    assert_bodies_bit_identical("e = 1", &on, &off);
    assert_ledger_identical("e = 1", &on, &off);
}

#[test]
fn pairs_of_fixed_bodies_skipped_leave_the_dynamic_bodies_bit_identical() {
    let s = spec();
    let build = || {
        let mut b = bed::build(&s);
        // The bottom layer (the first 36 bodies) is fixed: its neighbours are pairs of fixed bodies.
        for i in 0..36 {
            let fix = |body: &mut RigidBody| {
                body.motion = Motion::Fixed;
                body.velocity = Vector::zeros();
                body.angular_momentum = Vector::zeros();
            };
            b.world.edit_body(i, fix).expect("a body");
        }
        b
    };
    let (on, _) = run(build(), Skips::all(true));
    let (off, _) = run(build(), only(|k| k.non_dynamic_pairs = false));
    assert_bodies_bit_identical("fixed pairs", &on, &off);
    assert_ledger_identical("fixed pairs", &on, &off);
}

#[test]
fn bodies_without_angular_momentum_skip_the_rotation_exactly() {
    // Spheres in a sparse layer (no sphere–sphere contact), frictionless, falling onto the floor: the
    // contact point lies on the vertical through the centre, so every torque is exactly zero.
    let s = bed::BedSpec {
        friction: 0.0,
        speed: 0.0,
        gap: 0.5,
        ..bed::BedSpec::rocks([5, 5, 1], 1, 3)
    };
    let build = || {
        let mut b = bed::build(&s);
        for i in 0..b.world.body_count() {
            let r = b.world.radii()[i];
            let place = |body: &mut RigidBody| {
                body.angular_momentum = Vector::zeros();
                // 0.1 mm above the floor: it lands after ~140 steps.
                body.position.z = r + 1e-4;
            };
            b.world.edit_body(i, place).expect("a body");
        }
        b
    };
    let (on, _) = run(build(), Skips::all(true));
    // The isotropic fast path (on by default) would also skip the splitting of these spheres: off too.
    let (off, _) = run(
        build(),
        only(|k| {
            k.still_rotation = false;
            k.isotropic_rotation = false;
        }),
    );
    assert!(
        on.loads().wall_forces()[0].z < 0.0,
        "the spheres must reach the floor: force on the floor {:?}",
        on.loads().wall_forces()[0]
    );
    for (i, (a, b)) in on.bodies().iter().zip(off.bodies()).enumerate() {
        assert_eq!(a.angular_momentum, Vector::zeros(), "body {i} gained spin");
        assert_eq!(
            bits(a.position.coords.as_slice()),
            bits(b.position.coords.as_slice()),
            "body {i}: position on {:?} off {:?}",
            a.position,
            b.position
        );
        assert_eq!(
            bits(a.velocity.as_slice()),
            bits(b.velocity.as_slice()),
            "body {i}: velocity on {:?} off {:?}",
            a.velocity,
            b.velocity
        );
        let angle = a.orientation.angle_to(&b.orientation);
        assert!(
            angle <= 1e-15,
            "body {i}: orientations differ by {angle:e} rad, tolerance 1e-15 (renormalisation round-off)"
        );
    }
}

#[test]
fn query_skips_and_verlet_skin_agree_with_full_queries_within_tolerance() {
    let s = spec();
    let (on, c_on) = run(bed::build(&s), Skips::all(true));
    let (off, c_off) = run(
        bed::build(&s),
        only(|k| {
            k.bounding_spheres = false;
            k.cached_axis = false;
            k.verlet_skin = false;
        }),
    );
    // The skips must actually have skipped something.
    assert!(
        c_on[0] > 1000 && c_on[1] > 1000 && c_off[0] == 0 && c_off[1] == 0,
        "rejections (bounding sphere, cached axis): on {c_on:?}, off {c_off:?}"
    );
    assert!(
        c_on[2] < c_off[2] && c_on[3] < c_off[3],
        "GJK runs / rebuilds on {c_on:?} must be fewer than off {c_off:?}"
    );
    let d = bed::build(&s).diameter;
    let (mut dx, mut dv) = (0.0f64, 0.0f64);
    for (a, b) in on.bodies().iter().zip(off.bodies()) {
        dx = dx.max((a.position - b.position).norm());
        dv = dv.max((a.velocity - b.velocity).norm());
    }
    let rel = |x: f64, y: f64| (x - y).abs() / x.abs().max(y.abs());
    let (e_on, e_off) = (on.energy(), off.energy());
    let ke = rel(
        e_on.translational_kinetic + e_on.rotational_kinetic,
        e_off.translational_kinetic + e_off.rotational_kinetic,
    );
    let floor = rel(
        on.loads().wall_forces()[0].z,
        off.loads().wall_forces()[0].z,
    );
    eprintln!(
        "query skips on vs off after {STEPS} steps: max |Δx|/d = {:e}, max |Δv|/v0 = {:e}, kinetic energy {ke:e}, floor force {floor:e}; counters on {c_on:?} off {c_off:?}",
        dx / d,
        dv / s.speed
    );
    assert!(
        dx / d <= 1e-12,
        "max position difference {dx:e} m = {:e} d, tolerance 1e-12 d (d = {d} m)",
        dx / d
    );
    assert!(
        dv / s.speed <= 1e-12,
        "max velocity difference {dv:e} m/s, tolerance 1e-12 · {} m/s",
        s.speed
    );
    assert!(
        ke <= 1e-12,
        "kinetic energy differs by {ke:e} relative, tolerance 1e-12"
    );
    assert!(
        floor <= 1e-12,
        "floor force differs by {floor:e} relative, tolerance 1e-12"
    );
}
