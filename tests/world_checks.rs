//! The step's checks: a non-finite state is a typed error naming the body and the step (never carried on),
//! and an overlap deeper than the warning fraction of the particle size is reported.

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{Plane, Shape, Sphere};
use polydem::world::{
    step, ContactKey, MaterialTable, StepError, StepParams, StepScratch, Wall, World,
};

/// Two spheres of radius 0.05 m above a floor, with the linear law k_n: 'first' at height `z`, 'second' at
/// 0.5 m.
fn ball_over_floor(z: Real, k_n: Real) -> World {
    let mut materials = MaterialTable::default();
    let m = materials.add_material("m");
    materials.set_model(
        m,
        m,
        ContactModel {
            normal: NormalLaw::linear(k_n).unwrap(),
            damping: DampingLaw::None,
            tangential: TangentialLaw::None,
        },
    );
    let mut world = World::new(Vector::new(0.0, 0.0, -9.81), materials, 0.01);
    let sphere = Sphere::new(0.05).unwrap();
    let shape = world.add_shape(Shape::Sphere(sphere));
    let props = sphere.mass_properties();
    let body = RigidBody::new_dynamic(
        Point::new(0.0, 0.0, z),
        props.volume * 1000.0,
        PrincipalInertia::new(props.principal_moments * 1000.0).unwrap(),
    )
    .unwrap();
    world.add_body("first", shape, m, body).unwrap();
    let mut second = body;
    second.position = Point::new(1.0, 0.0, 0.5);
    world.add_body("second", shape, m, second).unwrap();
    world
        .add_wall(Wall {
            name: "floor".into(),
            plane: Plane::new(Vector::z(), 0.0).unwrap(),
            pose: Pose::from_parts(Vector::zeros().into(), Rotation::identity()),
            velocity: Vector::zeros(),
            material: m,
        })
        .unwrap();
    world
}

#[test]
fn a_non_finite_velocity_is_an_error_naming_body_and_step() {
    let mut world = ball_over_floor(0.5, 1e5);
    let params = StepParams::new(1e-4);
    let mut scratch = StepScratch::default();
    for _ in 0..3 {
        step(&params, &mut world, &mut scratch).expect("finite steps");
    }
    let nan = |b: &mut polydem::dynamics::RigidBody| b.velocity.y = Real::NAN;
    world.edit_body(1, nan).expect("body 1");
    let err = step(&params, &mut world, &mut scratch).expect_err("NaN velocity carried on");
    match &err {
        StepError::NonFinite {
            step, body, name, ..
        } => {
            assert_eq!((*step, *body, name.as_str()), (4, 1, "second"), "{err}");
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }
    let message = err.to_string();
    assert!(
        message.contains("step 4") && message.contains("'second'"),
        "{message}"
    );
}

#[test]
fn a_deep_overlap_is_reported() {
    // The sphere starts 10 % of its diameter inside the floor.
    let mut world = ball_over_floor(0.04, 1e5);
    let params = StepParams::new(1e-5);
    let report = step(&params, &mut world, &mut StepScratch::default()).expect("step");
    assert_eq!(report.overlap_warnings.len(), 1, "{report:?}");
    let w = report.overlap_warnings[0];
    assert_eq!(w.key, ContactKey::Wall { body: 0, wall: 0 });
    assert!(
        (w.ratio - 0.1).abs() < 1e-3,
        "overlap ratio {}, expected ≈ 0.1 (δ = 0.01 m, diameter 0.1 m)",
        w.ratio
    );
}

#[test]
fn an_invalid_time_step_is_refused() {
    let mut world = ball_over_floor(0.5, 1e5);
    for dt in [0.0, -1e-4, Real::NAN] {
        let err = step(
            &StepParams::new(dt),
            &mut world,
            &mut StepScratch::default(),
        );
        assert!(
            matches!(err, Err(StepError::InvalidTimeStep { .. })),
            "dt = {dt}: {err:?}"
        );
    }
}
