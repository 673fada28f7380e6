//! Seeded granular beds built in code, shared by the engine tests (`tests/world_*.rs`) and the step
//! benchmark (`benches/step.rs`, which includes this file by path).
//!
//! A bed is a lattice of particle columns in a box (floor and four side walls), columns `cell = (1 + gap)
//! · d` apart with `d` the largest bounding diameter, each particle `gap · d` above the top of the one below: a few distinct random convex hulls shared
//! by many bodies (and optionally spheres), random orientations, small random velocities, gravity. The
//! contact law is linear with damping from a restitution and a Coulomb spring; the time step is the
//! elastic contact time of the lightest pair divided by `steps_per_contact`.

#![allow(dead_code)]

use std::sync::Arc;

use polydem::dynamics::{PrincipalInertia, RigidBody};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{ConvexPolyhedron, Plane, Shape, Sphere};
use polydem::world::{MaterialTable, StepParams, Wall, World};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// What to build.
#[derive(Clone, Copy, Debug)]
pub struct BedSpec {
    /// Columns along x and y, bodies per column (bodies = product).
    pub cells: [usize; 3],
    /// Nominal particle diameter (m).
    pub size: Real,
    /// Distinct polyhedral hulls shared by the bodies.
    pub hull_shapes: usize,
    /// Points per hull (on a randomly stretched sphere).
    pub hull_points: usize,
    /// Every `sphere_every`-th body is a sphere (0: none).
    pub sphere_every: usize,
    /// Free gap between columns and between bodies in a column, as a fraction of the largest bounding
    /// diameter.
    pub gap: Real,
    /// Random initial speeds up to this (m/s), random spins up to `speed / size` (rad/s).
    pub speed: Real,
    pub restitution: Real,
    pub friction: Real,
    /// Linear normal stiffness (N/m); k_t = k_n / 2.
    pub stiffness: Real,
    pub density: Real,
    /// Δt = t_c / steps_per_contact.
    pub steps_per_contact: Real,
    pub seed: u64,
}

impl BedSpec {
    /// A rock bed of `cells` with mixed polyhedra and (every `sphere_every`-th) spheres, friction 0.5,
    /// restitution 0.3.
    pub fn rocks(cells: [usize; 3], sphere_every: usize, seed: u64) -> Self {
        Self {
            cells,
            size: 0.1,
            hull_shapes: 6,
            hull_points: 14,
            sphere_every,
            gap: 0.02,
            speed: 0.5,
            restitution: 0.3,
            friction: 0.5,
            stiffness: 1.0e6,
            density: 2600.0,
            steps_per_contact: 40.0,
            seed,
        }
    }
}

/// A built bed.
pub struct Bed {
    pub world: World,
    pub params: StepParams,
    /// Inner box: x, y in [0, extent[0|1]], floor at z = 0.
    pub extent: [Real; 3],
    /// The largest bounding diameter (m): the cell size without gap.
    pub diameter: Real,
    /// The contact model of every pair.
    pub model: ContactModel,
}

fn random_hull(rng: &mut ChaCha8Rng, radius: Real, points: usize) -> ConvexPolyhedron {
    let stretch = Vector::new(
        rng.random_range(0.75..1.0),
        rng.random_range(0.75..1.0),
        rng.random_range(0.75..1.0),
    );
    let pts: Vec<Point> = (0..points)
        .map(|_| {
            // Uniform direction from a normalised Gaussian-free method: rejection in the unit cube.
            loop {
                let v = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let n = v.norm();
                if n > 0.2 && n <= 1.0 {
                    return Point::from((v / n).component_mul(&stretch) * radius);
                }
            }
        })
        .collect();
    ConvexPolyhedron::from_points(&pts)
        .expect("random hull of points on a sphere")
        .0
}

/// How far the shape at `orientation` reaches below and above its centre (both ≥ 0, m).
fn z_extent(shape: &Shape, orientation: &Rotation) -> (Real, Real) {
    match shape {
        Shape::Polyhedron(p) => {
            let zs = p.vertices().iter().map(|v| (orientation * v).z);
            let lo = zs.clone().fold(Real::INFINITY, Real::min);
            let hi = zs.fold(Real::NEG_INFINITY, Real::max);
            (-lo, hi)
        }
        Shape::Sphere(s) => (s.radius(), s.radius()),
        Shape::Plane(_) => unreachable!("bed bodies are never planes"),
        other => match other.convex() {
            Some(c) => {
                let aabb = c.aabb(&Pose::from_parts(Vector::zeros().into(), *orientation));
                (-aabb.mins.z, aabb.maxs.z)
            }
            None => unreachable!("bed bodies are never planes"),
        },
    }
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Rotation {
    Rotation::from_euler_angles(
        rng.random_range(-3.1..3.1),
        rng.random_range(-1.5..1.5),
        rng.random_range(-3.1..3.1),
    )
}

/// The model every pair uses.
pub fn model_of(spec: &BedSpec) -> ContactModel {
    ContactModel {
        normal: NormalLaw::linear(spec.stiffness).expect("stiffness"),
        damping: DampingLaw::from_restitution(1.0, spec.restitution).expect("restitution"),
        tangential: if spec.friction > 0.0 {
            TangentialLaw::spring(0.5 * spec.stiffness, spec.friction).expect("spring")
        } else {
            TangentialLaw::None
        },
    }
}

/// Builds the bed of `spec`.
pub fn build(spec: &BedSpec) -> Bed {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let mut materials = MaterialTable::default();
    let rock = materials.add_material("rock");
    let model = model_of(spec);
    materials.set_model(rock, rock, model);
    let gravity = Vector::new(0.0, 0.0, -9.81);
    let mut world = World::new(gravity, materials, 0.05 * spec.size);

    let radius = 0.5 * spec.size;
    let mut shapes = Vec::new();
    for _ in 0..spec.hull_shapes {
        let hull = random_hull(&mut rng, radius, spec.hull_points);
        let props = (
            hull.mass_properties().volume,
            hull.mass_properties().principal_moments,
            hull.bounding_radius(),
        );
        shapes.push((world.add_shape(Shape::Polyhedron(Arc::new(hull))), props));
    }
    let sphere = Sphere::new(0.45 * spec.size).expect("sphere");
    let sphere_props = (
        sphere.mass_properties().volume,
        sphere.mass_properties().principal_moments,
        sphere.radius(),
    );
    let sphere_shape = world.add_shape(Shape::Sphere(sphere));
    let diameter = 2.0
        * shapes
            .iter()
            .map(|s| s.1 .2)
            .fold(sphere_props.2, Real::max);
    let cell = diameter * (1.0 + spec.gap);
    let extent = [
        cell * spec.cells[0] as Real,
        cell * spec.cells[1] as Real,
        cell * spec.cells[2] as Real,
    ];
    // Columns on an x–y lattice of `cell`; within a column each body sits `gap · d` above the top of the
    // one below it (actual extents of the rotated shape), so the bed starts nearly in contact.
    let mut lightest = Real::INFINITY;
    let mut index = 0;
    let mut column_top = vec![0.0; spec.cells[0] * spec.cells[1]];
    for _k in 0..spec.cells[2] {
        for j in 0..spec.cells[1] {
            for i in 0..spec.cells[0] {
                let (shape, (volume, moments, _)) = if spec.sphere_every > 0
                    && index % spec.sphere_every == spec.sphere_every - 1
                {
                    (sphere_shape, sphere_props)
                } else {
                    shapes[rng.random_range(0..shapes.len())]
                };
                let mass = volume * spec.density;
                lightest = lightest.min(mass);
                let inertia = PrincipalInertia::new(moments * spec.density).expect("inertia");
                let orientation = random_rotation(&mut rng);
                let (below, above) = z_extent(&world.shapes()[shape as usize], &orientation);
                let top = &mut column_top[i + spec.cells[0] * j];
                let z = *top + spec.gap * diameter + below;
                *top = z + above;
                let centre = Point::new((i as Real + 0.5) * cell, (j as Real + 0.5) * cell, z);
                let mut body = RigidBody::new_dynamic(centre, mass, inertia).expect("body");
                body.orientation = orientation;
                body.velocity = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                ) * spec.speed;
                let spin = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                ) * (spec.speed / spec.size);
                body.set_angular_velocity(&spin);
                world
                    .add_body(&format!("p{index}"), shape, rock, body)
                    .expect("body added");
                index += 1;
            }
        }
    }
    let walls = [
        ("floor", Vector::z(), 0.0),
        ("x0", Vector::x(), 0.0),
        ("x1", -Vector::x(), -extent[0]),
        ("y0", Vector::y(), 0.0),
        ("y1", -Vector::y(), -extent[1]),
    ];
    for (name, normal, offset) in walls {
        world
            .add_wall(Wall {
                name: name.to_owned(),
                plane: Plane::new(normal, offset).expect("plane"),
                pose: Pose::identity(),
                velocity: Vector::zeros(),
                material: rock,
            })
            .expect("wall added");
    }
    let t_c = model.normal.elastic_contact_time(0.5 * lightest, 1.0);
    let params = StepParams::new(t_c / spec.steps_per_contact);
    Bed {
        world,
        params,
        extent,
        diameter,
        model,
    }
}

/// Adds a projectile (a sphere of `radius`, density `density`) above the bed's centre at height `height`
/// above the top of the lattice, moving straight down at `speed`. Returns its body index.
pub fn add_projectile(
    bed: &mut Bed,
    radius: Real,
    density: Real,
    height: Real,
    speed: Real,
) -> usize {
    let sphere = Sphere::new(radius).expect("projectile radius");
    let props = sphere.mass_properties();
    let mass = props.volume * density;
    let inertia = PrincipalInertia::new(props.principal_moments * density).expect("inertia");
    let shape = bed.world.add_shape(Shape::Sphere(sphere));
    let top = bed
        .world
        .bodies()
        .iter()
        .zip(bed.world.radii())
        .map(|(b, r)| b.position.z + r)
        .fold(0.0, Real::max);
    let mut body = RigidBody::new_dynamic(
        Point::new(
            0.5 * bed.extent[0],
            0.5 * bed.extent[1],
            top + radius + height,
        ),
        mass,
        inertia,
    )
    .expect("projectile");
    body.velocity = Vector::new(0.0, 0.0, -speed);
    bed.world
        .add_body("projectile", shape, 0, body)
        .expect("projectile added") as usize
}
