//! A cube resting on an incline: the incline is a horizontal wall with gravity tilted by θ
//! (the same problem in the wall's frame); contact through the contact core's polyhedron–plane path, linear
//! normal law with restitution damping (e = 0.3), incremental tangential spring with Coulomb cap, body
//! integrator. Used by the `friction` case and by `tests/friction_gates.rs`.

use std::sync::Arc;

use polydem::contact::{
    query_with, ContactTolerances, EpaScratch, PairCache, QueryCounters, WallDepth,
};
use polydem::dynamics::{
    Integrator, Motion, PrincipalInertia, RigidBody, RotationScheme, TranslationParams,
    ViscousDamping,
};
use polydem::law::hertz_mindlin::linear_spring_dashpot;
use polydem::law::{ContactKinematics, TangentialHistory};
use polydem::math::{Point, Pose, Real, Vector};
use polydem::shape::{ConvexPolyhedron, Plane, Shape};

pub const SIDE: Real = 0.2;
pub const DENSITY: Real = 2600.0;
pub const G: Real = 9.81;
/// Normal and tangential stiffness of the linear law (N/m).
pub const STIFFNESS: Real = 2e7;

pub struct Run {
    /// Displacement along the slope (m) at the end.
    pub displacement: Real,
    /// Acceleration along the slope fitted over the second half of the run (m/s²).
    pub acceleration: Real,
    /// Largest rotation of the cube from its initial orientation (rad).
    pub max_tilt: Real,
}

/// The cube on the incline of angle `theta` with friction `mu`, for `duration` seconds. The wall contact
/// is the smoothed depth with its band set by the rule of `polydem::contact::wall_depth`: h = the static
/// overlap m g cos θ / k_n.
pub fn slide(theta: Real, mu: Real, duration: Real) -> Run {
    slide_with(theta, mu, duration, None)
}

/// [`slide`] with the given wall contact law (`None`: the smoothed depth with h = the static overlap).
pub fn slide_with(theta: Real, mu: Real, duration: Real, wall_depth: Option<WallDepth>) -> Run {
    let h = 0.5 * SIDE;
    let mut corners = Vec::new();
    for sx in [-h, h] {
        for sy in [-h, h] {
            for sz in [-h, h] {
                corners.push(Point::new(sx, sy, sz));
            }
        }
    }
    let cube = Arc::new(ConvexPolyhedron::from_points(&corners).expect("cube").0);
    let props = cube.mass_properties().clone();
    let mass = props.volume * DENSITY;
    let shape_b = Shape::Polyhedron(cube);
    let shape_a = Shape::Plane(Plane::new(Vector::z(), 0.0).unwrap());
    let (k_n, k_t) = (STIFFNESS, STIFFNESS);
    let model = linear_spring_dashpot(k_n, k_t, 0.3, mu).unwrap();
    let gravity = Vector::new(G * theta.sin(), 0.0, -G * theta.cos());
    let static_overlap = mass * G * theta.cos() / k_n;
    let tolerances = ContactTolerances {
        wall_depth: wall_depth.unwrap_or(WallDepth::Smoothed {
            band: static_overlap / shape_b.length_scale().expect("a polyhedron has a size"),
        }),
        ..ContactTolerances::default()
    };
    let mut wall = RigidBody::new_dynamic(
        Point::origin(),
        1.0,
        PrincipalInertia::new(Vector::repeat(1.0)).unwrap(),
    )
    .unwrap();
    wall.motion = Motion::Fixed;
    let mut body = RigidBody::new_dynamic(
        Point::new(0.0, 0.0, h - static_overlap),
        mass,
        PrincipalInertia::new(props.principal_inertia(DENSITY)).unwrap(),
    )
    .unwrap();
    let q0 = body.orientation;
    let dt = 2.0 * std::f64::consts::PI * (mass / k_n).sqrt() / 50.0;
    let integrator = Integrator {
        translation: TranslationParams {
            gravity,
            damping: ViscousDamping::None,
        },
        rotation: RotationScheme::default(),
    };
    let (mut cache, mut scratch, mut counters) = (
        PairCache::default(),
        EpaScratch::default(),
        QueryCounters::default(),
    );
    let mut history = TangentialHistory::default();
    let pose = |b: &RigidBody| Pose::from_parts(b.position.coords.into(), b.orientation);
    let mut evaluate = |body: &RigidBody, history: &mut TangentialHistory| {
        let g = query_with(
            &pose(&wall),
            &shape_a,
            &pose(body),
            &shape_b,
            &tolerances,
            &mut cache,
            &mut scratch,
            &mut counters,
        )
        .expect("plane–polyhedron");
        let kinematics = ContactKinematics {
            relative_velocity: body.velocity_at(&g.point),
            effective_mass: mass,
            center_a: wall.position,
            center_b: body.position,
            dt,
        };
        model.evaluate(&g, &kinematics, history)
    };
    let steps = (duration / dt) as usize;
    let mut response = evaluate(&body, &mut history);
    let mut samples = Vec::new();
    let mut max_tilt: Real = 0.0;
    for step in 0..steps {
        integrator.first_half_kick(&mut body, &response.force_on_b, &response.torque_on_b, dt);
        integrator.drift(&mut body, dt);
        response = evaluate(&body, &mut history);
        integrator.second_half_kick(&mut body, &response.force_on_b, &response.torque_on_b, dt);
        max_tilt = max_tilt.max(body.orientation.angle_to(&q0));
        if step >= steps / 2 {
            samples.push(((step + 1) as Real * dt, body.velocity.x));
        }
    }
    // Least-squares slope of v(t) over the second half.
    let n = samples.len() as Real;
    let (mt, mv) = (
        samples.iter().map(|s| s.0).sum::<Real>() / n,
        samples.iter().map(|s| s.1).sum::<Real>() / n,
    );
    let stv: Real = samples.iter().map(|s| (s.0 - mt) * (s.1 - mv)).sum();
    let stt: Real = samples.iter().map(|s| (s.0 - mt).powi(2)).sum();
    Run {
        displacement: body.position.x,
        acceleration: stv / stt,
        max_tilt,
    }
}
