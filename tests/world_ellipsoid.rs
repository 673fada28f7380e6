//! Ellipsoids through the whole engine, built with the library API (`Shape::ellipsoid`, `World::add_body`,
//! `step`): the generic support-map arm feeds the laws like any other contact.
//!
//! Time step and tolerance: a linear spring of stiffness k on a body of effective mass m_eff oscillates at
//! ω = √(k/m_eff). An eccentric contact lowers m_eff below m: 1/m_eff = 1/m + |r × n|²/J ≤ 1/m + R²/J_min
//! (R the bounding radius, J_min the least principal moment), which bounds ω by ω_max. Kick–drift–kick on a
//! harmonic oscillator keeps a modified energy, and the true energy deviates from it by at most
//! (ω Δt)²/4 of the oscillation energy; the tests allow (ω_max Δt)² of the impact energy (the factor 4 for
//! the contact's entry and exit within a step and the rotation's coupling) and report the measured figure.

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{Plane, Shape};
use polydem::world::{step, MaterialTable, StepParams, StepScratch, Wall, World};

const DENSITY: Real = 2500.0;
const STIFFNESS: Real = 1e7;
/// Steps per linear contact time of the body's own mass, π √(m/k).
const STEPS_PER_CONTACT: Real = 200.0;

fn elastic_world(gravity: Vector) -> (World, u32) {
    let mut materials = MaterialTable::default();
    let m = materials.add_material("grain");
    materials.set_model(
        m,
        m,
        ContactModel {
            normal: NormalLaw::linear(STIFFNESS).expect("stiffness"),
            damping: DampingLaw::from_restitution(1.0, 1.0).expect("restitution 1"),
            tangential: TangentialLaw::None,
        },
    );
    (World::new(gravity, materials, 0.01), m)
}

/// An ellipsoid body of the given semi-axes: (body, mass, bounding radius, least principal moment).
fn ellipsoid_body(
    world: &mut World,
    material: u32,
    name: &str,
    axes: [Real; 3],
    position: Point,
    orientation: Rotation,
    velocity: Vector,
) -> (Real, Real, Real) {
    let shape = Shape::ellipsoid(axes[0], axes[1], axes[2]).expect("semi-axes");
    let convex = shape.convex().expect("bounded");
    let props = convex.mass_properties();
    let (mass, moments) = (props.volume * DENSITY, props.principal_moments * DENSITY);
    let radius = convex.bounding_radius();
    let id = world.add_shape(shape);
    let inertia = PrincipalInertia::new(moments).expect("inertia");
    let mut body = RigidBody::new_dynamic(position, mass, inertia).expect("body");
    body.orientation = orientation;
    body.velocity = velocity;
    world.add_body(name, id, material, body).expect("add body");
    (mass, radius, moments.min())
}

/// ω_max Δt for a body of mass `m`, bounding radius `r` and least moment `j` (see the module docs).
fn omega_dt(m: Real, r: Real, j: Real, dt: Real) -> Real {
    let m_eff_min = 1.0 / (1.0 / m + r * r / j);
    (STIFFNESS / m_eff_min).sqrt() * dt
}

#[test]
fn tilted_ellipsoid_bouncing_on_a_wall_conserves_energy() {
    let g = 9.81;
    let (mut world, mat) = elastic_world(Vector::new(0.0, 0.0, -g));
    world
        .add_wall(Wall {
            name: "floor".into(),
            plane: Plane::new(Vector::z(), 0.0).expect("plane"),
            pose: Pose::identity(),
            velocity: Vector::zeros(),
            material: mat,
        })
        .expect("wall");
    let orientation = Rotation::from_euler_angles(0.4, -0.3, 0.2);
    let axes = [0.2, 0.1, 0.05];
    // The lowest point starts 1 cm above the floor, falling at 1 m/s.
    let low = Shape::ellipsoid(axes[0], axes[1], axes[2])
        .expect("semi-axes")
        .convex()
        .expect("bounded")
        .aabb(&Pose::from_parts(Vector::zeros().into(), orientation))
        .mins
        .z;
    let start = Point::new(0.0, 0.0, 0.01 - low);
    let v0 = Vector::new(0.0, 0.0, -1.0);
    let (m, r, j) = ellipsoid_body(&mut world, mat, "e", axes, start, orientation, v0);
    let dt = std::f64::consts::PI * (m / STIFFNESS).sqrt() / STEPS_PER_CONTACT;
    let impact = 0.5 * m * v0.norm_squared() + m * g * 0.01;
    let tol = omega_dt(m, r, j, dt).powi(2) * impact;
    let params = StepParams::new(dt);
    let mut scratch = StepScratch::default();
    let (mut worst, mut contact_steps) = (0.0 as Real, 0usize);
    for _ in 0..3000 {
        let report = step(&params, &mut world, &mut scratch).expect("step");
        contact_steps += report.contacts;
        worst = worst.max(world.energy().balance.abs());
    }
    let e = world.energy();
    // The wall's impulse per unit mass: the velocity gained over free fall (most of the impact goes into
    // spin for this eccentric, end-first contact).
    let free_fall = v0.z - g * world.time();
    let gained = world.bodies()[0].velocity.z - free_fall;
    assert!(
        contact_steps > 50 && gained > 0.5,
        "the wall stopped the fall: {contact_steps} contact steps, velocity gained over free fall {gained} m/s"
    );
    assert!(
        e.rotational_kinetic > 1e-3 * impact,
        "the tilted impact spins the body: T_rot {:e} J, impact energy {impact:e} J",
        e.rotational_kinetic
    );
    eprintln!(
        "ellipsoid on a wall: dt {dt:e} s, max |balance| {worst:e} J = {:e} of the impact energy, tolerance {:e}",
        worst / impact,
        tol / impact
    );
    assert!(
        worst <= tol,
        "max |balance| {worst:e} J, tolerance (ω_max Δt)² E_impact = {tol:e} J (E_impact {impact:e} J, dt {dt:e} s)"
    );
}

#[test]
fn elastic_ellipsoid_impact_recovers_kinetic_energy() {
    let (mut world, mat) = elastic_world(Vector::zeros());
    let axes_a = [0.1, 0.06, 0.03];
    let axes_b = [0.08, 0.08, 0.02];
    let qa = Rotation::from_euler_angles(0.3, 0.2, -0.5);
    let qb = Rotation::from_euler_angles(-0.7, 0.4, 1.1);
    // Start 2 mm apart along x by the bounding boxes (a lower bound of the gap), closing at 2 m/s.
    let half_x = |axes: [Real; 3], q: Rotation| {
        let e = Shape::ellipsoid(axes[0], axes[1], axes[2]).expect("semi-axes");
        e.convex()
            .expect("bounded")
            .aabb(&Pose::from_parts(Vector::zeros().into(), q))
            .maxs
            .x
    };
    let xb = half_x(axes_a, qa) + half_x(axes_b, qb) + 0.002;
    let (ma, ra, ja) = ellipsoid_body(
        &mut world,
        mat,
        "a",
        axes_a,
        Point::origin(),
        qa,
        Vector::new(1.0, 0.0, 0.0),
    );
    let (mb, rb, jb) = ellipsoid_body(
        &mut world,
        mat,
        "b",
        axes_b,
        Point::new(xb, 0.02, 0.01),
        qb,
        Vector::new(-1.0, 0.0, 0.0),
    );
    let dt = std::f64::consts::PI * (ma.min(mb) / STIFFNESS).sqrt() / STEPS_PER_CONTACT;
    let t0 = {
        let e = world.energy();
        e.translational_kinetic + e.rotational_kinetic
    };
    let p0 = world.linear_momentum();
    let tol = omega_dt(ma, ra, ja, dt)
        .max(omega_dt(mb, rb, jb, dt))
        .powi(2)
        * t0;
    let params = StepParams::new(dt);
    let mut scratch = StepScratch::default();
    let mut contact_steps = 0usize;
    for _ in 0..8000 {
        contact_steps += step(&params, &mut world, &mut scratch)
            .expect("step")
            .contacts;
    }
    let e = world.energy();
    let t1 = e.translational_kinetic + e.rotational_kinetic;
    assert!(
        contact_steps > 50 && e.elastic_potential == 0.0,
        "the bodies collided and separated: {contact_steps} contact steps, U_el {:e} J",
        e.elastic_potential
    );
    assert!(
        e.rotational_kinetic > 1e-3 * t0,
        "the eccentric impact spins the bodies: T_rot {:e} J of T0 {t0:e} J",
        e.rotational_kinetic
    );
    let dp = (world.linear_momentum() - p0).norm();
    assert!(
        dp <= 1e-12 * (ma + mb),
        "momentum change {dp:e} kg·m/s, tolerance {:e}",
        1e-12 * (ma + mb)
    );
    eprintln!(
        "ellipsoid impact: dt {dt:e} s, |T1 − T0|/T0 {:e}, tolerance {:e}",
        (t1 - t0).abs() / t0,
        tol / t0
    );
    assert!(
        (t1 - t0).abs() <= tol,
        "kinetic energy after the impact {t1:e} J, before {t0:e} J, tolerance (ω_max Δt)² T0 = {tol:e} J"
    );
}
