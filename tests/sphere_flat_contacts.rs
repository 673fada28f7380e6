//! The flat sphere path (`src/world/sphere_flat/`) on the smallest scenes: two spheres colliding, against
//! closed forms and the general step, and its neighbour lists against a brute-force pair search.
//!
//! - Head-on impact of two equal Hertz spheres with restitution e: the rebound speed over the approach
//!   speed is e (the damping law's closed form, exact for the continuous impact; the discrete step at
//!   Δt = t_c/2000 leaves a few 1e-4, see `src/law/damping.rs` and `reports/restitution.md`).
//! - Oblique impact of stiff spheres, fast enough along the tangent to slide throughout: each sphere's tangential velocity changes by
//!   μ J_n / m (J_n the normal impulse, measured), and its spin by the same impulse's moment r μ J_n / J.
//! - Both impacts take the same bits on the flat path as on the general step.
//! - Lists: random polydisperse spheres (and three large ones, which the grid leaves out) in a box of five
//!   walls, moving several skins during the run: after every step every overlapping pair and body–wall
//!   pair is listed, and every list built equals the brute-force set of pairs within the skin (the wider
//!   skin of the large ones for their pairs).

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::law::hertz_mindlin::{hertz_mindlin, ElasticMaterial, SpherePair};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Vector};
use polydem::shape::{Plane, Shape, Sphere};
use polydem::world::{step, MaterialTable, SphereSim, StepParams, StepScratch, Wall, World};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const RADIUS: Real = 2e-3;
const DENSITY: Real = 2500.0;

fn world_with(model: ContactModel, skin: Real) -> (World, u32) {
    let mut materials = MaterialTable::default();
    let m = materials.add_material("bed");
    materials.set_model(m, m, model);
    (World::new(Vector::zeros(), materials, skin), m)
}

fn add_sphere(world: &mut World, material: u32, radius: Real, x: Point, v: Vector) -> usize {
    let sphere = Sphere::new(radius).expect("sphere");
    let props = sphere.mass_properties();
    let shape = world.add_shape(Shape::Sphere(sphere));
    let inertia = PrincipalInertia::new(props.principal_moments * DENSITY).expect("inertia");
    let mut body = RigidBody::new_dynamic(x, props.volume * DENSITY, inertia).expect("body");
    body.velocity = v;
    let n = world.bodies().len();
    world
        .add_body(&format!("s{n}"), shape, material, body)
        .expect("body added") as usize
}

fn hertz(young: Real, restitution: Real, friction: Real) -> ContactModel {
    let bed = ElasticMaterial::new(young, 0.2).expect("material");
    hertz_mindlin(&SpherePair {
        material_a: bed,
        material_b: bed,
        radius_a: RADIUS,
        radius_b: Some(RADIUS),
        restitution,
        friction,
    })
    .expect("model")
}

/// Two equal spheres approaching along x at relative speed `vn`, sliding past each other along y at
/// relative speed `vt`, run on the flat path until they part; returns (flat world, general world, dt).
fn impact(model: ContactModel, vn: Real, vt: Real) -> (World, World) {
    let (mut world, m) = world_with(model, 0.1 * RADIUS);
    // Touching at the start: the contact begins with the first step.
    let gap = 0.0;
    add_sphere(
        &mut world,
        m,
        RADIUS,
        Point::new(-RADIUS - gap, 0.0, 0.0),
        Vector::new(0.5 * vn, -0.5 * vt, 0.0),
    );
    add_sphere(
        &mut world,
        m,
        RADIUS,
        Point::new(RADIUS + gap, 0.0, 0.0),
        Vector::new(-0.5 * vn, 0.5 * vt, 0.0),
    );
    let mass = world.bodies()[0].mass;
    let t_c = model.normal.elastic_contact_time(0.5 * mass, vn);
    let mut params = StepParams::new(t_c / 2000.0);
    params.energy_ledger = false;
    let steps = (3.0 * t_c / params.dt) as u64;
    let mut flat = SphereSim::from_world(&world, &params).expect("two spheres take the flat path");
    let mut general = world.clone();
    let mut scratch = StepScratch::default();
    for _ in 0..steps {
        flat.step().expect("flat step");
        step(&params, &mut general, &mut scratch).expect("general step");
    }
    flat.write_back(&mut world);
    (world, general)
}

fn assert_same_bits(label: &str, a: &World, b: &World) {
    for (i, (x, y)) in a.bodies().iter().zip(b.bodies()).enumerate() {
        let bits = |b: &RigidBody| {
            [b.position.coords, b.velocity, b.angular_momentum]
                .iter()
                .flat_map(|v| v.iter().map(|x| x.to_bits()))
                .collect::<Vec<_>>()
        };
        assert_eq!(
            bits(x),
            bits(y),
            "{label}: body {i} flat {x:?} against general {y:?}"
        );
    }
}

#[test]
fn head_on_impact_rebounds_with_the_restitution() {
    let (e, vn) = (0.5, 1.0);
    let (flat, general) = impact(hertz(1e9, e, 0.3), vn, 0.0);
    assert_same_bits("head-on impact", &flat, &general);
    let rebound = flat.bodies()[1].velocity.x - flat.bodies()[0].velocity.x;
    let measured = rebound / vn;
    let tolerance = 2e-3;
    assert!(
        (measured - e).abs() < tolerance,
        "head-on Hertz impact at {vn} m/s, Δt = t_c/2000: restitution {measured}, expected {e} \
         (tolerance {tolerance})"
    );
}

#[test]
fn oblique_sliding_impact_transfers_mu_times_the_normal_impulse() {
    // Stiff and slow, so that the spheres slide past each other by little during the contact (the normal
    // turns by ~v_t t_c / 2R, which the closed form with a fixed normal leaves out).
    let (e, mu, vn) = (0.5, 0.3, 0.02);
    // Sliding throughout needs v_t > 3.5 μ (1 + e) v_n for two equal solid spheres; take 5 times that.
    let vt = 5.0 * 3.5 * mu * (1.0 + e) * vn;
    // With the force limit the normal force never pulls (the cap μ max(F_n, 0) then sees all of J_n).
    let mut model = hertz(210e9, e, mu);
    model.normal = model.normal.with_force_limit();
    let (flat, general) = impact(model, vn, vt);
    assert_same_bits("oblique impact", &flat, &general);
    let body = &flat.bodies()[1];
    let (mass, moment) = (body.mass, body.inertia.0.x);
    let normal_impulse = mass * (body.velocity.x - (-0.5 * vn));
    let tangential_change = body.velocity.y - 0.5 * vt;
    let expected = -mu * normal_impulse / mass;
    // The closed form takes the normal fixed; it turns by up to θ = v_t t_c / 2R during the contact, which
    // tilts the normal force (μ⁻¹ times the friction) by up to θ into the tangent: 2θ/μ. Measured besides
    // it: a residual of 1.7e-3 that changes neither with Δt (t_c/500 … t_c/8000) nor with θ
    // (v_n 0.02 … 0.0002 m/s), not explained (a guess: the incremental spring sticks for a few steps at
    // the end of the contact, where the Mindlin k_t ∝ √δ vanishes); the tolerance takes 2.5e-3 for it.
    let t_c = model.normal.elastic_contact_time(0.5 * mass, vn);
    let turn = vt * t_c / (2.0 * RADIUS);
    let tolerance = 2.5e-3 + 2.0 * turn / mu;
    assert!(
        (tangential_change - expected).abs() < tolerance * expected.abs(),
        "oblique impact v_n {vn}, v_t {vt} m/s, μ {mu}: tangential velocity change {tangential_change}, \
         expected −μ J_n/m = {expected} (relative tolerance {tolerance}: turn of the normal {turn})"
    );
    // The friction impulse acts at the contact point, r from the centre along −x: spin about z.
    let spin = body.angular_momentum.z / moment;
    let expected_spin = RADIUS * mu * normal_impulse / moment;
    assert!(
        (spin - expected_spin).abs() < tolerance * expected_spin.abs(),
        "oblique impact: spin {spin} rad/s, expected r μ J_n / J = {expected_spin} (relative tolerance \
         {tolerance})"
    );
}

#[test]
fn lists_hold_every_touching_pair_after_motions_of_several_skins() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261122);
    // A soft linear law: the spheres fly through each other nearly undisturbed.
    let model = ContactModel {
        normal: NormalLaw::linear(1e-3).expect("law"),
        damping: DampingLaw::None,
        tangential: TangentialLaw::None,
    };
    let skin = 0.2 * RADIUS;
    let (mut world, m) = world_with(model, skin);
    let size = 40.0 * RADIUS;
    for k in 0..603 {
        let r = if k % 200 == 199 {
            4.0 * RADIUS
        } else {
            RADIUS * rng.random_range(0.5..1.0)
        };
        let x = Point::new(
            rng.random_range(r..size - r),
            rng.random_range(r..size - r),
            rng.random_range(r..size - r),
        );
        let v = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        add_sphere(&mut world, m, r, x, v);
    }
    let walls = [
        (Vector::z(), 0.0),
        (Vector::x(), 0.0),
        (-Vector::x(), -size),
        (Vector::y(), 0.0),
        (-Vector::y(), -size),
    ];
    for (k, (normal, offset)) in walls.into_iter().enumerate() {
        world
            .add_wall(Wall {
                name: format!("w{k}"),
                plane: Plane::new(normal, offset).expect("plane"),
                pose: Pose::identity(),
                velocity: Vector::zeros(),
                material: m,
            })
            .expect("wall");
    }
    // Each step moves the fastest spheres about a third of the skin.
    let mut params = StepParams::new(0.3 * skin / 3.0f64.sqrt());
    params.energy_ledger = false;
    let mut flat = SphereSim::from_world(&world, &params).expect("flat path");
    let radii: Vec<Real> = world
        .bodies()
        .iter()
        .enumerate()
        .map(|(i, _)| world.radii()[i])
        .collect();
    let n = radii.len();
    let mut builds_checked = 0;
    let mut last_builds = flat.neighbours().builds();
    for step_index in 0..60 {
        flat.step().expect("flat step");
        let x: Vec<Point> = (0..n).map(|i| flat.position(i)).collect();
        let listed: std::collections::BTreeSet<(u32, u32)> = flat.body_pairs().collect();
        let walls_listed: std::collections::BTreeSet<(u32, u32)> = flat.wall_pairs().collect();
        let fresh = flat.neighbours().builds() != last_builds;
        last_builds = flat.neighbours().builds();
        let mut within_skin = std::collections::BTreeSet::new();
        for i in 0..n {
            for j in i + 1..n {
                let d = (x[j] - x[i]).norm();
                let key = (i as u32, j as u32);
                assert!(
                    d >= radii[i] + radii[j] || listed.contains(&key),
                    "step {step_index}: spheres {i} and {j} overlap (distance {d}, radii {} + {}) but \
                     are not listed",
                    radii[i],
                    radii[j]
                );
                let lists = flat.neighbours();
                let pair_skin = lists.skin_of(i).max(lists.skin_of(j));
                if d < radii[i] + radii[j] + pair_skin {
                    within_skin.insert(key);
                }
            }
            for (w, (normal, offset)) in walls.iter().enumerate() {
                let height = normal.dot(&x[i].coords) - offset;
                assert!(
                    height >= radii[i] || walls_listed.contains(&(i as u32, w as u32)),
                    "step {step_index}: sphere {i} reaches wall {w} (height {height}, radius {}) but is \
                     not listed",
                    radii[i]
                );
            }
        }
        if fresh {
            // The step's build was at the positions the drift reached: the lists are the brute-force set.
            assert_eq!(
                listed, within_skin,
                "step {step_index}: the rebuilt list differs from the brute-force pairs within the skin"
            );
            builds_checked += 1;
        }
    }
    let moved = (0..n)
        .map(|i| (flat.position(i) - world.bodies()[i].position).norm())
        .fold(0.0, Real::max);
    assert!(
        builds_checked >= 5 && moved > 5.0 * skin,
        "the run must rebuild (checked {builds_checked} builds, expected ≥ 5) and move several skins \
         (largest displacement {moved} m, skin {skin} m)"
    );
}
