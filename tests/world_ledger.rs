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
        max_wall_force = max_wall_force.max(-world.loads.wall_forces[0].z);
    }
    let v = world.bodies[0].velocity.z;
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
        world.contacts.is_empty(),
        "the pair should have left the store: {:?}",
        world.contacts.keys()
    );
}
