//! One contact between two bodies, integrated by the body integrator (kick–drift–kick) until the bodies
//! separate, with the contact geometry supplied by the caller: closed-form sphere–sphere and sphere–wall
//! geometry here, or the contact core's `query` (polyhedra). Measures the peak normal force, the peak
//! overlap and the contact duration (start and end interpolated linearly in the signed overlap between
//! steps), and returns the bodies after separation.
//!
//! Convention: body A is below, B above; the geometry's normal points from A to B; forces on B are
//! `force_on_b`, on A its opposite.

use polydem::contact::{ContactGeometry, ContactKind, SolverStatus};
use polydem::dynamics::{Integrator, RigidBody, RotationScheme, TranslationParams, ViscousDamping};
use polydem::law::{ContactKinematics, ContactModel, TangentialHistory};
use polydem::math::{Point, Real, Vector};

/// The result of one impact.
#[derive(Clone, Debug)]
pub struct Impact {
    /// Largest elastic + damping normal force seen (N).
    pub peak_force: Real,
    /// Largest overlap (m).
    pub peak_overlap: Real,
    /// Contact duration (s), start and end interpolated in the signed overlap.
    pub duration: Real,
    /// Body A after separation (or at the step limit).
    pub a: RigidBody,
    /// Body B after separation (or at the step limit).
    pub b: RigidBody,
    /// Whether the contact ended within the step limit.
    pub separated: bool,
}

/// Signed overlap of a geometry: depth when overlapping, minus the distance otherwise.
pub fn signed_overlap(g: &ContactGeometry) -> Real {
    if g.kind == ContactKind::Overlap {
        g.depth
    } else {
        -g.distance
    }
}

fn geometry_from(normal: Vector, depth: Real, point_a: Point, point_b: Point) -> ContactGeometry {
    ContactGeometry::from_points(
        if depth > 0.0 {
            ContactKind::Overlap
        } else {
            ContactKind::Separated
        },
        depth.max(0.0),
        (-depth).max(0.0),
        normal,
        point_a,
        point_b,
        SolverStatus::Exact,
    )
}

/// Closed-form geometry of two spheres of radii `radius_a`, `radius_b` centred on the bodies.
pub fn sphere_sphere(
    radius_a: Real,
    radius_b: Real,
    a: &RigidBody,
    b: &RigidBody,
) -> ContactGeometry {
    let d = b.position - a.position;
    let n = d / d.norm();
    geometry_from(
        n,
        radius_a + radius_b - d.norm(),
        a.position + n * radius_a,
        b.position - n * radius_b,
    )
}

/// Closed-form geometry of the wall z = 0 (body A, normal +z) and a sphere of radius `radius` (body B).
pub fn wall_sphere(radius: Real, b: &RigidBody) -> ContactGeometry {
    let n = Vector::z();
    geometry_from(
        n,
        radius - b.position.z,
        Point::new(b.position.x, b.position.y, 0.0),
        b.position - n * radius,
    )
}

/// Integrates the impact of A and B with time step `dt` for at most `max_steps` steps, stopping at
/// separation. `effective_mass` is the m* handed to the law (damping); `geometry` gives the contact geometry
/// of the current poses.
pub fn impact(
    model: &ContactModel,
    mut a: RigidBody,
    mut b: RigidBody,
    effective_mass: Real,
    dt: Real,
    max_steps: usize,
    mut geometry: impl FnMut(&RigidBody, &RigidBody) -> ContactGeometry,
) -> Impact {
    let integrator = Integrator {
        translation: TranslationParams {
            gravity: Vector::zeros(),
            damping: ViscousDamping::None,
        },
        rotation: RotationScheme::default(),
    };
    let mut history = TangentialHistory::default();
    let mut evaluate = |a: &RigidBody, b: &RigidBody, history: &mut TangentialHistory| {
        let g = geometry(a, b);
        let kinematics = ContactKinematics {
            relative_velocity: b.velocity_at(&g.point) - a.velocity_at(&g.point),
            effective_mass,
            center_a: a.position,
            center_b: b.position,
            dt,
        };
        (model.evaluate(&g, &kinematics, history), signed_overlap(&g))
    };
    let (mut response, mut overlap) = evaluate(&a, &b, &mut history);
    let (mut peak_force, mut peak_overlap): (Real, Real) = (0.0, 0.0);
    let (mut start, mut end) = (if overlap > 0.0 { Some(0.0) } else { None }, None);
    for step in 0..max_steps {
        integrator.first_half_kick(&mut a, &-response.force_on_b, &response.torque_on_a, dt);
        integrator.first_half_kick(&mut b, &response.force_on_b, &response.torque_on_b, dt);
        integrator.drift(&mut a, dt);
        integrator.drift(&mut b, dt);
        let previous = overlap;
        (response, overlap) = evaluate(&a, &b, &mut history);
        integrator.second_half_kick(&mut a, &-response.force_on_b, &response.torque_on_a, dt);
        integrator.second_half_kick(&mut b, &response.force_on_b, &response.torque_on_b, dt);
        peak_force = peak_force.max(response.normal_force);
        peak_overlap = peak_overlap.max(overlap);
        let t = (step as Real + previous / (previous - overlap)) * dt;
        if previous <= 0.0 && overlap > 0.0 && start.is_none() {
            start = Some(t);
        }
        if previous > 0.0 && overlap <= 0.0 && start.is_some() {
            end = Some(t);
            break;
        }
    }
    let duration = match (start, end) {
        (Some(s), Some(e)) => e - s,
        _ => Real::NAN,
    };
    Impact {
        peak_force,
        peak_overlap,
        duration,
        a,
        b,
        separated: end.is_some(),
    }
}

/// Hertz's elastic impact (Johnson 1985, §11.4) for effective modulus E*, radius R*, mass m* and approach
/// speed v: δ_max = (15 m* v²/(16 E* √R*))^(2/5), F_max = (4/3) E* √R* δ_max^(3/2), t_c = 2 I δ_max/v with
/// I = ∫₀¹ (1 − x^(5/2))^(−1/2) dx = 1.4716… (evaluated by quadrature after x = 1 − s², which removes the
/// end-point singularity). Returns (F_max, δ_max, t_c).
pub fn hertz_theory(
    young_effective: Real,
    radius_effective: Real,
    mass_effective: Real,
    speed: Real,
) -> (Real, Real, Real) {
    let delta = (15.0 * mass_effective * speed * speed
        / (16.0 * young_effective * radius_effective.sqrt()))
    .powf(0.4);
    let force = 4.0 / 3.0 * young_effective * radius_effective.sqrt() * delta.powf(1.5);
    let panels = 100_000;
    let h = 1.0 / panels as Real;
    let integral: Real = (0..panels)
        .map(|i| {
            let s = (i as Real + 0.5) * h;
            let x: Real = 1.0 - s * s;
            2.0 * s * h / (1.0 - x.powf(2.5)).sqrt()
        })
        .sum();
    (force, delta, 2.0 * integral * delta / speed)
}
