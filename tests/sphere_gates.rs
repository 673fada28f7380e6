//! Sphere impacts against closed-form answers: Hertz elastic impact
//! (peak force, peak overlap, contact duration), restitution against a wall, and an oblique impact in gross
//! sliding against the rigid-body impulse solution. Laws from `polydem::law::hertz_mindlin`, integration by
//! the body integrator through the shared driver `polydem_validation::sim::two_body`; sphere–sphere and
//! sphere–wall geometry in closed form there (the contact core's fast
//! paths are not used, so these gates test the laws and the integrator only).

use polydem::dynamics::{Motion, PrincipalInertia, RigidBody};
use polydem::law::hertz_mindlin::{
    effective, effective_young_modulus, hertz_mindlin, ElasticMaterial, SpherePair,
};
use polydem::law::ContactModel;
use polydem::math::{Point, Real, Vector};
use polydem_validation::sim::two_body;

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

/// Integrates until the contact has ended (shared driver `polydem_validation::sim::two_body::impact`);
/// dt = t_c/`per_contact` (t_c of the elastic law at the approach speed).
fn impact(
    partner: Partner,
    model: &ContactModel,
    a: RigidBody,
    b: RigidBody,
    per_contact: Real,
) -> two_body::Impact {
    let m_star = match partner {
        Partner::Sphere => a.mass * b.mass / (a.mass + b.mass),
        Partner::Wall => b.mass,
    };
    let approach = match partner {
        Partner::Sphere => -(b.velocity - a.velocity).dot(&(b.position - a.position).normalize()),
        Partner::Wall => -b.velocity.z,
    };
    let dt = model.normal.elastic_contact_time(m_star, approach) / per_contact;
    let outcome = two_body::impact(
        model,
        a,
        b,
        m_star,
        dt,
        (20.0 * per_contact) as usize,
        |a, b| match partner {
            Partner::Sphere => two_body::sphere_sphere(RADIUS, RADIUS, a, b),
            Partner::Wall => two_body::wall_sphere(RADIUS, b),
        },
    );
    assert!(outcome.separated, "contact did not end");
    outcome
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

/// Hertz theory (Johnson 1985, §11.4) through `two_body::hertz_theory`: (F_max, δ_max, t_c).
fn hertz_theory(partner: Partner, mass: Real, speed: Real) -> (Real, Real, Real) {
    let e_star = effective_young_modulus(&material(), &material());
    let (r_star, m_star) = match partner {
        Partner::Sphere => (effective(RADIUS, Some(RADIUS)), effective(mass, Some(mass))),
        Partner::Wall => (RADIUS, mass),
    };
    two_body::hertz_theory(e_star, r_star, m_star, speed)
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
        let measured = outcome.b.velocity.z / speed;
        println!("sphere–wall e = {e}: measured {measured}");
        assert!(
            (measured - e).abs() < 0.01 * e,
            "Hertz sphere–wall, v = {speed} m/s, dt = t_c/400: restitution {measured}, input {e}, tolerance 1 %"
        );
        assert_eq!(outcome.a.velocity, Vector::zeros(), "the fixed wall moved");
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
    let after = outcome.b;
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
