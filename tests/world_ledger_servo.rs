//! The energy ledger books the work of a wall whose velocity a controller changes between steps
//! (src/world/energy.rs, `StepPowers::at_start`).
//!
//! A sphere sits on a floor that recedes at a constant speed, under a top wall driven like the rockfill
//! compaction's servo: the wall moves down at twice the floor's speed while its contact force is below a
//! cap and stops when it is above, so once it has reached the sphere its velocity switches between two
//! values from one step to the next (the force relaxes as the floor recedes). The external work is the trapezoid of
//! −F·v_wall over each step; taking the start of a step with the velocity of the previous evaluation
//! (before the servo changed it) booked work for steps in which the wall did not move and missed half of
//! the steps in which it did: the compaction ledgers of the rockfill packing then missed 50–58 % of the
//! wall's work. With the step's own velocity at both ends, what is left is the quadrature error of the
//! conservative forces.

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{Plane, Shape, Sphere};
use polydem::world::{step, MaterialTable, StepParams, StepScratch, Wall, World};

const RADIUS: Real = 2e-3;
const DENSITY: Real = 2500.0;
const STIFFNESS: Real = 2e4;

/// Runs the servo for `steps` steps at Δt = t_c/`per_contact`; returns (|balance| at the end, external
/// work, number of velocity switches).
fn servo_run(per_contact: Real, steps: usize) -> (Real, Real, usize) {
    let mut materials = MaterialTable::default();
    let grain = materials.add_material("grain");
    materials.set_model(
        grain,
        grain,
        ContactModel {
            normal: NormalLaw::linear(STIFFNESS).unwrap(),
            damping: DampingLaw::dashpot(0.5).unwrap(),
            tangential: TangentialLaw::spring(0.5 * STIFFNESS, 0.3).unwrap(),
        },
    );
    let props = Sphere::new(RADIUS).unwrap().mass_properties();
    let mass = props.volume * DENSITY;
    let t_c = std::f64::consts::PI * (mass / STIFFNESS).sqrt();
    // The cap: 50 weights; the wall's speed closes 1 % of the radius in 5 contact times.
    let cap = 50.0 * mass * 9.81;
    let speed = 0.002 * RADIUS / t_c;
    let mut world = World::new(Vector::new(0.0, 0.0, -9.81), materials, 0.5 * RADIUS);
    let ball = world.add_shape(Shape::Sphere(Sphere::new(RADIUS).unwrap()));
    let body = RigidBody::new_dynamic(
        Point::new(0.0, 0.0, RADIUS),
        mass,
        PrincipalInertia::new(props.principal_moments * DENSITY).unwrap(),
    )
    .unwrap();
    world.add_body("ball", ball, grain, body).unwrap();
    for (name, normal, height) in [
        ("floor", Vector::z(), 0.0),
        ("top", -Vector::z(), 2.0 * RADIUS + 0.01 * RADIUS),
    ] {
        world
            .add_wall(Wall {
                name: name.into(),
                plane: Plane::new(normal, 0.0).unwrap(),
                pose: Pose::from_parts(Vector::new(0.0, 0.0, height).into(), Rotation::identity()),
                velocity: Vector::new(0.0, 0.0, if name == "floor" { -0.5 * speed } else { 0.0 }),
                material: grain,
            })
            .unwrap();
    }
    let params = StepParams::new(t_c / per_contact);
    let mut scratch = StepScratch::default();
    let mut switches = 0;
    let mut last_moving = false;
    for _ in 0..steps {
        let force = world.loads().wall_forces().get(1).map_or(0.0, |f| f.z);
        let moving = force < cap;
        switches += usize::from(moving != last_moving);
        last_moving = moving;
        let velocity = if moving {
            Vector::new(0.0, 0.0, -speed)
        } else {
            Vector::zeros()
        };
        world.set_wall_velocity(1, velocity).expect("wall 1");
        step(&params, &mut world, &mut scratch).expect("step");
    }
    let e = world.energy();
    (e.balance.abs(), e.external_work, switches)
}

#[test]
fn a_servo_wall_books_the_work_it_does() {
    // 20 contact times at t_c/50, then the same at t_c/100: the error relative to the wall's work must be
    // small and shrink with Δt (the stale velocity gave an error of the order of the work at any Δt).
    let (balance_coarse, work_coarse, switches_coarse) = servo_run(50.0, 1000);
    let (balance_fine, work_fine, switches_fine) = servo_run(100.0, 2000);
    assert!(
        switches_coarse > 20 && switches_fine > 20,
        "the servo must switch often to test anything: {switches_coarse} and {switches_fine} switches"
    );
    let (rel_coarse, rel_fine) = (balance_coarse / work_coarse, balance_fine / work_fine);
    println!("servo: t_c/50 {rel_coarse:.3e} ({switches_coarse} switches), t_c/100 {rel_fine:.3e} ({switches_fine} switches)");
    let tol = 1e-2;
    assert!(
        rel_coarse < tol && rel_fine < tol,
        "|balance| / external work at t_c/50: {rel_coarse:.3e} ({balance_coarse:.3e} J of \
         {work_coarse:.3e} J), at t_c/100: {rel_fine:.3e} ({balance_fine:.3e} J of {work_fine:.3e} J); \
         tol {tol}"
    );
    assert!(
        rel_fine < rel_coarse,
        "the error must shrink with Δt: {rel_coarse:.3e} at t_c/50, {rel_fine:.3e} at t_c/100"
    );
}
