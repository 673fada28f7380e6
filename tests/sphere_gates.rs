//! Sphere impacts against closed-form answers (issue 3, gates 3 and 5, sphere part): Hertz elastic impact
//! (peak force, peak overlap, contact duration), restitution against a wall, and an oblique impact in gross
//! sliding against the rigid-body impulse solution. Laws from `polydem::law::hertz_mindlin`, integration by
//! the body integrator; sphere–sphere and sphere–wall geometry in closed form here (the contact core's fast
//! paths are not used, so these gates test the laws and the integrator only).

use polydem::contact::{ContactGeometry, ContactKind, SolverStatus};
use polydem::dynamics::{
    Integrator, Motion, PrincipalInertia, RigidBody, RotationScheme, TranslationParams,
    ViscousDamping,
};
use polydem::law::hertz_mindlin::{
    effective, effective_young_modulus, hertz_mindlin, ElasticMaterial, SpherePair,
};
use polydem::law::{ContactKinematics, ContactModel, ContactResponse, TangentialHistory};
use polydem::math::{Point, Real, Vector};

/// Aluminium-like material and a 0.1 m sphere at 10 m/s: chosen by us, not quoted from a paper.
const RADIUS: Real = 0.1;
const DENSITY: Real = 2700.0;

fn material() -> ElasticMaterial {
    ElasticMaterial::new(7.0e10, 0.3).unwrap()
}

fn sphere(center: Point, velocity: Vector) -> RigidBody {
    let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    let inertia = PrincipalInertia::new(Vector::repeat(0.4 * mass * RADIUS * RADIUS)).unwrap();
    let mut body = RigidBody::new_dynamic(center, mass, inertia).unwrap();
    body.velocity = velocity;
    body
}

/// Body A is either a sphere or the wall z = 0 (normal +z, A below).
#[derive(Clone, Copy, PartialEq)]
enum Partner {
    Sphere,
    Wall,
}

fn geometry(partner: Partner, a: &RigidBody, b: &RigidBody) -> ContactGeometry {
    let (normal, depth, point_a) = match partner {
        Partner::Sphere => {
            let d = b.position - a.position;
            let n = d / d.norm();
            (n, 2.0 * RADIUS - d.norm(), a.position + n * RADIUS)
        }
        Partner::Wall => {
            let n = Vector::z();
            (
                n,
                RADIUS - b.position.z,
                Point::new(b.position.x, b.position.y, 0.0),
            )
        }
    };
    let point_b = b.position - normal * RADIUS;
    ContactGeometry {
        kind: if depth > 0.0 {
            ContactKind::Overlap
        } else {
            ContactKind::Separated
        },
        depth: depth.max(0.0),
        distance: (-depth).max(0.0),
        normal,
        point_a,
        point_b,
        point: Point::from((point_a.coords + point_b.coords) * 0.5),
        status: SolverStatus::Exact,
    }
}

struct Impact {
    peak_force: Real,
    peak_overlap: Real,
    duration: Real,
    b_after: RigidBody,
    a_after: RigidBody,
}

/// Integrates until the contact has ended; dt = t_c/`per_contact` (t_c of the elastic law at the approach
/// speed). Contact start and end times are interpolated linearly in the overlap between steps.
fn impact(
    partner: Partner,
    model: &ContactModel,
    mut a: RigidBody,
    mut b: RigidBody,
    per_contact: Real,
) -> Impact {
    let m_star = match partner {
        Partner::Sphere => a.mass * b.mass / (a.mass + b.mass),
        Partner::Wall => b.mass,
    };
    let approach = -(b.velocity - a.velocity).dot(&geometry(partner, &a, &b).normal);
    let dt = model.normal.elastic_contact_time(m_star, approach) / per_contact;
    let integrator = Integrator {
        translation: TranslationParams {
            gravity: Vector::zeros(),
            damping: ViscousDamping::None,
        },
        rotation: RotationScheme::default(),
    };
    let mut history = TangentialHistory::default();
    let evaluate = |a: &RigidBody,
                    b: &RigidBody,
                    history: &mut TangentialHistory|
     -> (ContactResponse, Real) {
        let g = geometry(partner, a, b);
        let kinematics = ContactKinematics {
            relative_velocity: b.velocity_at(&g.point) - a.velocity_at(&g.point),
            effective_mass: m_star,
            center_a: a.position,
            center_b: b.position,
            dt,
        };
        // Signed overlap for interpolating the contact start and end.
        let signed = if g.kind == ContactKind::Overlap {
            g.depth
        } else {
            -g.distance
        };
        (model.evaluate(&g, &kinematics, history), signed)
    };
    let (mut response, mut overlap) = evaluate(&a, &b, &mut history);
    let (mut peak_force, mut peak_overlap): (Real, Real) = (0.0, 0.0);
    let (mut start, mut end) = (None, None);
    for step in 0..(20.0 * per_contact) as usize {
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
    let (start, end) = (
        start.expect("no contact"),
        end.expect("contact did not end"),
    );
    Impact {
        peak_force,
        peak_overlap,
        duration: end - start,
        b_after: b,
        a_after: a,
    }
}

fn pair(partner: Partner, restitution: Real, friction: Real) -> SpherePair {
    SpherePair {
        material_a: material(),
        material_b: material(),
        radius_a: RADIUS,
        radius_b: match partner {
            Partner::Sphere => Some(RADIUS),
            Partner::Wall => None,
        },
        restitution,
        friction,
    }
}

/// Hertz (Johnson 1985, §11.4): δ_max = (15 m* v²/(16 E* √R*))^(2/5), F_max = (4/3) E* √R* δ_max^(3/2),
/// t_c = 2.9432 δ_max/v, the constant being 2∫₀¹(1 − x^(5/2))^(−1/2) dx (evaluated by quadrature here).
fn hertz_theory(partner: Partner, mass: Real, speed: Real) -> (Real, Real, Real) {
    let e_star = effective_young_modulus(&material(), &material());
    let (r_star, m_star) = match partner {
        Partner::Sphere => (effective(RADIUS, Some(RADIUS)), effective(mass, Some(mass))),
        Partner::Wall => (RADIUS, mass),
    };
    let delta = (15.0 * m_star * speed * speed / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let force = 4.0 / 3.0 * e_star * r_star.sqrt() * delta.powf(1.5);
    // Midpoint rule after x = 1 − s², which removes the end-point singularity.
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

#[test]
fn elastic_hertz_impact_matches_peak_force_overlap_and_duration() {
    let speed = 10.0;
    for partner in [Partner::Sphere, Partner::Wall] {
        let model = hertz_mindlin(&pair(partner, 1.0, 0.0)).unwrap();
        let (a, b) = match partner {
            Partner::Sphere => (
                sphere(Point::origin(), Vector::new(0.0, 0.0, 0.5 * speed)),
                sphere(
                    Point::new(0.0, 0.0, 2.0 * RADIUS + 1e-4),
                    Vector::new(0.0, 0.0, -0.5 * speed),
                ),
            ),
            Partner::Wall => {
                let mut wall = sphere(Point::origin(), Vector::zeros());
                wall.motion = Motion::Fixed;
                (
                    wall,
                    sphere(
                        Point::new(0.0, 0.0, RADIUS + 1e-4),
                        Vector::new(0.0, 0.0, -speed),
                    ),
                )
            }
        };
        let mass = b.mass;
        let outcome = impact(partner, &model, a, b, 400.0);
        let (force, delta, duration) = hertz_theory(partner, mass, speed);
        let name = if partner == Partner::Sphere {
            "sphere–sphere"
        } else {
            "sphere–wall"
        };
        for (quantity, measured, expected) in [
            ("peak force (N)", outcome.peak_force, force),
            ("peak overlap (m)", outcome.peak_overlap, delta),
            ("contact duration (s)", outcome.duration, duration),
        ] {
            let error = (measured - expected).abs() / expected;
            println!("{name}: {quantity} relative error {error:e}");
            assert!(
                error < 1e-3,
                "{name}, v = {speed} m/s, dt = t_c/400: {quantity} = {measured:e}, Hertz {expected:e}, relative error {error:e}, tolerance 1e-3"
            );
        }
    }
}

#[test]
fn sphere_wall_restitution_equals_the_input() {
    let speed = 2.0;
    for e in [0.3, 0.6, 0.9] {
        let model = hertz_mindlin(&pair(Partner::Wall, e, 0.0)).unwrap();
        let mut wall = sphere(Point::origin(), Vector::zeros());
        wall.motion = Motion::Fixed;
        let ball = sphere(
            Point::new(0.0, 0.0, RADIUS + 1e-5),
            Vector::new(0.0, 0.0, -speed),
        );
        let outcome = impact(Partner::Wall, &model, wall, ball, 400.0);
        let measured = outcome.b_after.velocity.z / speed;
        println!("sphere–wall e = {e}: measured {measured}");
        assert!(
            (measured - e).abs() < 0.01 * e,
            "Hertz sphere–wall, v = {speed} m/s, dt = t_c/400: restitution {measured}, input {e}, tolerance 1 %"
        );
        assert_eq!(
            outcome.a_after.velocity,
            Vector::zeros(),
            "the fixed wall moved"
        );
    }
}

#[test]
fn oblique_impact_in_gross_sliding_matches_the_impulse_solution() {
    // Rigid-body impulse theory: with sliding throughout the contact, the tangential impulse is μ times the
    // normal one, J_n = m (1 + e) v_n, so v_t' = v_t − μ(1 + e)v_n and ω' = (5/2) μ (1 + e) v_n / R (about
    // the axis n × t); sliding persists when v_t > (7/2) μ (1 + e) v_n. Here v_t/v_n = 10, μ = 0.2, e = 0.8:
    // (7/2)·0.2·1.8 = 1.26 < 10. The lever arm of the contact force is R − δ/2 and the spring needs a few steps
    // to reach the Coulomb cap, both ≪ 1 % here.
    let (v_n, v_t, mu, e) = (1.0, 10.0, 0.2, 0.8);
    let model = hertz_mindlin(&pair(Partner::Wall, e, mu)).unwrap();
    let mut wall = sphere(Point::origin(), Vector::zeros());
    wall.motion = Motion::Fixed;
    let ball = sphere(
        Point::new(0.0, 0.0, RADIUS + 1e-5),
        Vector::new(v_t, 0.0, -v_n),
    );
    let outcome = impact(Partner::Wall, &model, wall, ball, 400.0);
    let after = outcome.b_after;
    let expected_vt = v_t - mu * (1.0 + e) * v_n;
    let expected_spin = 2.5 * mu * (1.0 + e) * v_n / RADIUS; // about +y: the rolling sense for motion along +x
    let checks = [
        ("normal rebound v_n'", after.velocity.z, e * v_n),
        ("tangential v_t'", after.velocity.x, expected_vt),
        ("spin ω_y'", after.angular_velocity().y, expected_spin),
    ];
    for (quantity, measured, expected) in checks {
        let error = (measured - expected).abs() / expected.abs();
        println!("oblique: {quantity} relative error {error:e}");
        assert!(
            error < 0.01,
            "oblique impact v_n = {v_n}, v_t = {v_t}, μ = {mu}, e = {e}: {quantity} = {measured}, expected {expected}, relative error {error:e}, tolerance 1 %"
        );
    }
}

#[test]
fn sliding_sphere_starts_rolling_at_five_sevenths_of_its_speed() {
    // A sphere launched without spin on a horizontal wall under gravity slides until v = ωR, then rolls:
    // the friction impulse gives v = (5/7) v₀ whatever μ (angular momentum about the contact point is
    // conserved). It starts at the static overlap δ = (m g / k_n)^(2/3) so that the contact persists.
    let (v0, mu, g) = (1.0, 0.3, 9.81);
    let model = hertz_mindlin(&pair(Partner::Wall, 0.5, mu)).unwrap();
    let mass = sphere(Point::origin(), Vector::zeros()).mass;
    let run = polydem_validation::sim::rolling::roll(&model, RADIUS, mass, v0, mu, g, 3.0);
    let lost_contact = run.lost_contact;
    assert_eq!(
        lost_contact, 0,
        "the sphere left the wall in {lost_contact} steps"
    );
    let (v, rolling) = (run.velocity, run.rolling_speed);
    let expected = 5.0 / 7.0 * v0;
    println!("rolling: v/v0 = {}, ωR/v0 = {}", v / v0, rolling / v0);
    assert!(
        (v - expected).abs() < 0.01 * expected,
        "after 3 sliding times: v = {v} m/s, expected 5/7 v₀ = {expected} m/s (μ = {mu}), tolerance 1 %"
    );
    assert!(
        (rolling - v).abs() < 0.01 * expected,
        "not rolling: ωR = {rolling} m/s, v = {v} m/s, tolerance 1 % of 5/7 v₀"
    );
}
