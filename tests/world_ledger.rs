//! The energy ledger's external work, through the `World` API (no scene file): a sphere at rest is struck
//! by a wall moving with a prescribed velocity u, elastically. In the wall's frame the sphere arrives at
//! −u and leaves at +u, so it ends with velocity 2u (closed form) and kinetic energy ½ m (2u)², all of it
//! work done by the wall: the ledger's `external_work` must equal it and the balance stay near zero.
//! Also: the wall reports the reaction force, and the pair leaves the contact store once the sphere is
//! out of reach.

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{Plane, Shape, Sphere};
use polydem::world::{step, MaterialTable, StepParams, StepScratch, Wall, World};

#[test]
fn a_prescribed_wall_does_the_work_the_ledger_reports() {
    let (radius, density, k_n, u): (Real, Real, Real, Real) = (0.05, 2500.0, 1e6, 0.5);
    let mut materials = MaterialTable::default();
    let glass = materials.add_material("glass");
    materials.set_model(
        glass,
        glass,
        ContactModel {
            normal: NormalLaw::linear(k_n).unwrap(),
            damping: DampingLaw::None,
            tangential: TangentialLaw::None,
        },
    );
    let mut world = World::new(Vector::zeros(), materials, 0.01);
    let sphere = Sphere::new(radius).unwrap();
    let shape = world.add_shape(Shape::Sphere(sphere));
    let props = sphere.mass_properties();
    let mass = props.volume * density;
    let body = RigidBody::new_dynamic(
        Point::new(0.0, 0.0, 0.1),
        mass,
        PrincipalInertia::new(props.principal_moments * density).unwrap(),
    )
    .unwrap();
    world.add_body("ball", shape, glass, body).unwrap();
    world
        .add_wall(Wall {
            name: "piston".into(),
            plane: Plane::new(Vector::z(), 0.0).unwrap(),
            pose: Pose::from_parts(Vector::new(0.0, 0.0, 0.04).into(), Rotation::identity()),
            velocity: Vector::new(0.0, 0.0, u),
            material: glass,
        })
        .unwrap();
    let t_c = std::f64::consts::PI * (mass / k_n).sqrt();
    let params = StepParams::new(t_c / 200.0);
    let mut scratch = StepScratch::default();
    let mut max_wall_force: Real = 0.0;
    // The gap of 0.01 m closes in 0.02 s; the contact lasts t_c; then the sphere (2u) outruns the wall (u).
    let steps = ((0.02 + t_c + 0.05) / params.dt) as usize;
    for _ in 0..steps {
        step(&params, &mut world, &mut scratch).expect("step");
        max_wall_force = max_wall_force.max(-world.loads().wall_forces()[0].z);
    }
    let v = world.bodies()[0].velocity.z;
    assert!(
        (v - 2.0 * u).abs() <= 1e-3 * u,
        "final velocity {v} m/s, expected 2u = {} m/s, tolerance 1e-3 u",
        2.0 * u
    );
    let e = world.energy();
    let expected_work = 0.5 * mass * (2.0 * u).powi(2);
    assert!(
        (e.external_work - expected_work).abs() <= 1e-3 * expected_work,
        "external work {} J, expected ½ m (2u)² = {expected_work} J, tolerance 1e-3",
        e.external_work
    );
    assert!(
        e.balance.abs() <= 1e-4 * expected_work,
        "balance {} J, tolerance 1e-4 × {expected_work} J",
        e.balance
    );
    // Peak force of a linear impact at relative speed u: k δ_max = u √(k m).
    let peak = u * (k_n * mass).sqrt();
    assert!(
        (max_wall_force - peak).abs() <= 1e-3 * peak,
        "peak reaction on the wall {max_wall_force} N, expected u√(km) = {peak} N"
    );
    assert!(
        world.contacts().is_empty(),
        "the pair should have left the store: {:?}",
        world.contacts().keys()
    );
}

/// One oblique bounce of a spinning sphere on a fixed wall, elastic normal law, Coulomb friction (μ = 0.5)
/// with a tangential spring: it slides, then sticks, so the spring loads and unloads while the cap changes.
/// Returns (ledger balance, friction work) after the sphere has left the wall, at Δt = t_c / `per_contact`.
fn oblique_spinning_bounce(per_contact: Real) -> (Real, Real) {
    let (radius, density, k_n, k_t, mu): (Real, Real, Real, Real, Real) =
        (0.02, 2600.0, 2e5, 1e5, 0.5);
    let mut materials = MaterialTable::default();
    let rock = materials.add_material("rock");
    materials.set_model(
        rock,
        rock,
        ContactModel {
            normal: NormalLaw::linear(k_n).unwrap(),
            damping: DampingLaw::None,
            tangential: TangentialLaw::spring(k_t, mu).unwrap(),
        },
    );
    let mut world = World::new(Vector::zeros(), materials, 0.004);
    let sphere = Sphere::new(radius).unwrap();
    let shape = world.add_shape(Shape::Sphere(sphere));
    let props = sphere.mass_properties();
    let mass = props.volume * density;
    let mut body = RigidBody::new_dynamic(
        Point::new(0.0, 0.0, radius + 0.001),
        mass,
        PrincipalInertia::new(props.principal_moments * density).unwrap(),
    )
    .unwrap();
    body.velocity = Vector::new(1.0, 0.3, -0.9);
    body.set_angular_velocity(&Vector::new(5.0, -3.0, 2.0));
    world.add_body("ball", shape, rock, body).unwrap();
    world
        .add_wall(Wall {
            name: "floor".into(),
            plane: Plane::new(Vector::z(), 0.0).unwrap(),
            pose: Pose::identity(),
            velocity: Vector::zeros(),
            material: rock,
        })
        .unwrap();
    let t_c = std::f64::consts::PI * (mass / k_n).sqrt();
    let params = StepParams::new(t_c / per_contact);
    let mut scratch = StepScratch::default();
    // The 1 mm gap closes in ~1.1 ms; the contact lasts t_c ≈ 2.1 ms; run 10 ms in all.
    let steps = (0.01 / params.dt) as usize;
    for _ in 0..steps {
        step(&params, &mut world, &mut scratch).expect("step");
    }
    assert!(
        world.bodies()[0].velocity.z > 0.0 && world.contacts().is_empty(),
        "the sphere should have bounced off: v = {:?}",
        world.bodies()[0].velocity
    );
    let e = world.energy();
    (e.balance, e.dissipated_friction)
}

/// The friction work of the ledger is the discrete work of the tangential spring (src/law/tangential.rs).
/// Measured on this bounce (|balance| / friction work): 1.1e-4 at t_c/50, 4.0e-6 at t_c/100, 2.0e-6 at
/// t_c/200, 1.2e-7, 1.7e-8 and 1.6e-9 at t_c/400…1600, since the ledger books the release of the spring
/// in the step the contact opens and the work of the last spring force with the lever arms the integrator
/// applied it with (src/world/energy.rs); before that: 1.7e-2, 2.6e-3, 8.4e-5, 5.2e-5, 3.7e-5, 2.8e-6.
/// The earlier rectangle rule (μF_n × slip) left 6 % of the friction work of the same kind of bounce
/// unaccounted at t_c/83, converging at first order. Gate: the single-contact tolerance, 1e-4,
/// from t_c/200 on, and at least second-order improvement (16×) from t_c/50 to t_c/200.
#[test]
fn friction_work_closes_the_ledger_of_a_spinning_bounce() {
    let mut coarse = None;
    for per_contact in [50.0, 200.0, 400.0, 800.0] {
        let (balance, friction) = oblique_spinning_bounce(per_contact);
        assert!(
            friction > 0.0,
            "t_c/{per_contact}: no friction work ({friction} J)"
        );
        let relative = balance.abs() / friction;
        match coarse {
            None => coarse = Some(relative),
            Some(at_50) => {
                assert!(
                    relative <= 1e-4,
                    "t_c/{per_contact}: |balance| {balance:e} J is {relative:e} of the friction work \
                     {friction:e} J, tolerance 1e-4"
                );
                assert!(
                    relative <= at_50 / 16.0,
                    "t_c/{per_contact}: relative balance {relative:e} not 16× below {at_50:e} at t_c/50"
                );
            }
        }
    }
}
