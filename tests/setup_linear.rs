//! Setting up a world is linear in the number of bodies. The material check of each added body (a law with
//! the material of every body already present) looks each distinct material up once, not every body
//! (which would make set-up quadratic); these tests count the work ([`polydem::world::SetupStats`]) rather than time it, and
//! check that the errors are those of the full scan.

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{Plane, Shape, Sphere};
use polydem::world::{MaterialTable, Wall, World, WorldError};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn model() -> ContactModel {
    ContactModel {
        normal: NormalLaw::linear(1e5).unwrap(),
        damping: DampingLaw::None,
        tangential: TangentialLaw::None,
    }
}

/// `n` materials; the law of the pair (a, b) is set unless `missing(a, b)`.
fn materials(n: u32, missing: impl Fn(u32, u32) -> bool) -> MaterialTable {
    let mut table = MaterialTable::default();
    for k in 0..n {
        table.add_material(&format!("m{k}"));
    }
    for a in 0..n {
        for b in a..n {
            if !missing(a, b) {
                table.set_model(a, b, model());
            }
        }
    }
    table
}

fn wall(k: usize, material: u32) -> Wall {
    Wall {
        name: format!("w{k}"),
        plane: Plane::new(Vector::z(), 0.0).unwrap(),
        pose: Pose::from_parts(
            Vector::new(0.0, 0.0, -(k as Real)).into(),
            Rotation::identity(),
        ),
        velocity: Vector::zeros(),
        material,
    }
}

fn sphere_body(i: usize) -> RigidBody {
    let props = Sphere::new(0.01).unwrap().mass_properties();
    RigidBody::new_dynamic(
        Point::new(i as Real * 0.03, 0.0, 0.0),
        props.volume * 1000.0,
        PrincipalInertia::new(props.principal_moments * 1000.0).unwrap(),
    )
    .unwrap()
}

/// A world of six walls and `n` spheres cycling through three materials; returns the set-up work.
fn set_up(n: usize) -> u64 {
    let mut world = World::new(Vector::zeros(), materials(3, |_, _| false), 0.001);
    let shape = world.add_shape(Shape::Sphere(Sphere::new(0.01).unwrap()));
    for k in 0..6 {
        world.add_wall(wall(k, (k % 3) as u32)).unwrap();
    }
    for i in 0..n {
        world
            .add_body(&format!("b{i}"), shape, (i % 3) as u32, sphere_body(i))
            .unwrap();
    }
    world.setup_stats().total()
}

#[test]
fn setup_work_grows_linearly_with_the_number_of_bodies() {
    let (small, large) = (10_000, 100_000);
    let (work_small, work_large) = (set_up(small), set_up(large));
    let ratio = work_large as Real / work_small as Real;
    // Each body: one record, at most 3 look-ups of body materials, 6 wall reads and look-ups, one of its
    // own material: 17 units. A quadratic check would do ~n/2 per body.
    let per_body_bound = 17;
    for (n, work) in [(small, work_small), (large, work_large)] {
        assert!(
            work <= per_body_bound * n as u64 + 64,
            "{n} bodies: set-up work {work}, expected at most {per_body_bound} per body"
        );
    }
    assert!(
        (ratio - 10.0).abs() <= 0.1,
        "work for {large} bodies / work for {small} bodies = {work_large} / {work_small} = {ratio:.4}, expected 10 ± 0.1 (linear)"
    );
}

/// The error a scan of every body, then every wall, then the body's own material gives: the reference the
/// presence table must reproduce.
fn scan_reference(
    table: &MaterialTable,
    bodies: &[u32],
    walls: &[u32],
    material: u32,
    owner: &str,
) -> Result<(), WorldError> {
    let others = bodies
        .iter()
        .chain(walls)
        .copied()
        .chain(std::iter::once(material));
    for other in others {
        if table.model(material, other).is_none() {
            return Err(WorldError::MissingLaw {
                owner: owner.to_owned(),
                a: table.name(material).to_owned(),
                b: table.name(other).to_owned(),
            });
        }
    }
    Ok(())
}

/// Random worlds of five materials with some laws missing: every add_body answers as the full scan does
/// (same acceptance, same message naming the same pair), including after walls are removed.
#[test]
fn material_checks_report_the_missing_law_of_the_full_scan() {
    let mut rng = ChaCha8Rng::seed_from_u64(30);
    let (mut accepted, mut refused) = (0, 0);
    for case in 0..200 {
        let holes: Vec<(u32, u32)> = (0..rng.random_range(0..4))
            .map(|_| (rng.random_range(0..5), rng.random_range(0..5)))
            .collect();
        let missing = |a: u32, b: u32| {
            holes
                .iter()
                .any(|&(x, y)| (x, y) == (a, b) || (y, x) == (a, b))
        };
        let table = materials(5, missing);
        let mut world = World::new(Vector::zeros(), table.clone(), 0.001);
        let shape = world.add_shape(Shape::Sphere(Sphere::new(0.01).unwrap()));
        let mut walls = Vec::new();
        for k in 0..rng.random_range(0..3) {
            let m = rng.random_range(0..5);
            if world.add_wall(wall(k, m)).is_ok() {
                walls.push(m);
            }
        }
        let mut bodies = Vec::new();
        for i in 0..40 {
            if i == 20 && !walls.is_empty() {
                // Walls removed between adds (as a penetration run removes the container's sides).
                world.truncate_walls(walls.len() - 1);
                walls.pop();
            }
            let m = rng.random_range(0..5);
            let name = format!("b{i}");
            let want = scan_reference(&table, &bodies, &walls, m, &name);
            let got = world.add_body(&name, shape, m, sphere_body(i)).map(|_| ());
            assert_eq!(
                got, want,
                "case {case}, body {i} of material {m}, holes {holes:?}"
            );
            if got.is_ok() {
                bodies.push(m);
                accepted += 1;
            } else {
                refused += 1;
            }
        }
    }
    assert!(
        accepted > 1000 && refused > 100,
        "the cases exercise both answers: {accepted} accepted, {refused} refused"
    );
}

/// A world read back from its serialised form (as a checkpoint is) checks against all its bodies.
#[test]
fn a_deserialised_world_checks_new_bodies_against_all_its_bodies() {
    let table = materials(2, |a, b| (a, b) == (0, 1));
    let mut world = World::new(Vector::zeros(), table, 0.001);
    let shape = world.add_shape(Shape::Sphere(Sphere::new(0.01).unwrap()));
    world.add_body("a", shape, 0, sphere_body(0)).unwrap();
    let text = serde_json::to_string(&world).unwrap();
    let mut restored: World = serde_json::from_str(&text).unwrap();
    let got = restored.add_body("b", shape, 1, sphere_body(1));
    assert_eq!(
        got,
        Err(WorldError::MissingLaw {
            owner: "b".into(),
            a: "m1".into(),
            b: "m0".into()
        }),
        "a body of m1 added to a restored world holding a body of m0, with no m0–m1 law"
    );
}
