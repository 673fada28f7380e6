//! The polyhedral bed of the sphere-bed penetration: every sphere of the settled sphere bed
//! (`reference/sphere_bed/bed_quick.csv`) replaced by a random convex polyhedron of the same volume.
//!
//! # Shapes
//! Body `k` (0-based row of the sphere file) draws, from `ChaCha8Rng::seed_from_u64(SEED)` on stream `k`, a
//! count n uniform in [[`MIN_POINTS`], [`MAX_POINTS`]] and n points uniform on the unit sphere (rejection
//! in the cube, then normalised: only IEEE-exact operations but one cosine, so the points are the same on
//! every platform), each at least [`MIN_SPACING`] of the mean spacing away from the others (dart
//! throwing). Its shape is the convex hull of these points, translated to put the hull's centroid at the
//! origin and scaled by (V_sphere / V_hull)^(1/3), so that its volume is the sphere's, (4/3)πr³. The
//! points are isotropic, so the orientation of the shape is uniformly random by construction; no separate
//! rotation is drawn. A hull of 12–20 random points on a sphere has 20–36 triangular faces and a
//! circumradius of about 1.15–1.25 times the equal-volume radius, so its vertices stick out of the
//! sphere it replaces.
//!
//! # Overlaps
//! Placed at the spheres' centres, the polyhedra overlap their neighbours and the walls (the spheres
//! touched). They are neither shrunk nor deformed: the overlaps are removed by moving the centroids
//! ([`push_apart`]: Gauss–Seidel sweeps that separate every overlapping pair along the EPA normal n_M by its
//! Minkowski overlap δ_M plus a gap, half to each body, and push every body out of the walls), which lifts
//! the bed a little (the top is open), then the bed settles under gravity with the bed's own Hertz–Mindlin
//! law (the settling run of the example `generate_polyhedra_bed`); the settled positions and orientations
//! are the data file `reference/sphere_bed/polyhedra_bed.csv`, and [`bed_bodies`] rebuilds the bodies from
//! it and from the seed.

use std::fmt::Write as _;
use std::path::Path;

use polydem::contact::contact_polyhedron_polyhedron::query_polyhedra;
use polydem::contact::ContactKind;
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::scene::body_file::{read_sphere_table, SphereRow};
use polydem::shape::ConvexPolyhedron;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Seed of the shapes (fixed, so that the polyhedral bed is the same on every run).
pub const SEED: u64 = 20261121;
/// Fewest hull points per shape.
pub const MIN_POINTS: usize = 12;
/// Most hull points per shape.
pub const MAX_POINTS: usize = 20;
/// Smallest angle between two points of a shape, as a fraction of the mean spacing √(4π/n) of n points
/// on the unit sphere: keeps slivers and flat shapes out (a hull of 12 unrestricted random points is at
/// times a flat sliver of a small fraction of the ball's volume, whose scaled vertices reach about twice the sphere's
/// radius). Measured on the 3000 shapes of the bed: circumradius / equal-volume radius median 1.20, largest
/// 1.43 with 0.7 (0.5: largest 1.67; 0.8 jams the dart throwing for 12 points).
pub const MIN_SPACING: Real = 0.7;

/// One polyhedron of the bed: its vertices about its centroid (m, world-aligned axes) and where its
/// centroid is.
#[derive(Clone, Debug)]
pub struct BedBody {
    /// The `id` of the sphere it replaces.
    pub id: String,
    /// The radius of that sphere (m): the equal-volume radius of the polyhedron.
    pub radius: Real,
    /// Hull vertices relative to the centroid, in the body's own frame (m).
    pub points: Vec<Point>,
    /// Centroid position (m).
    pub position: Vector,
    /// Orientation of the body's own frame (identity before settling).
    pub orientation: Rotation,
}

/// A point uniform on the unit sphere (rejection in the cube [−1, 1]³, then normalised).
fn unit_point(rng: &mut ChaCha8Rng) -> Vector {
    loop {
        let v = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n2 = v.norm_squared();
        if n2 > 1e-2 && n2 <= 1.0 {
            return v / n2.sqrt();
        }
    }
}

/// The shape of body `index` replacing a sphere of radius `radius` (see the module docs): hull vertices
/// about the centroid, volume (4/3)π r³.
pub fn shape_points(index: usize, radius: Real) -> Result<Vec<Point>, String> {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    rng.set_stream(index as u64);
    let n = rng.random_range(MIN_POINTS..=MAX_POINTS);
    // Dart throwing: a new point closer than the minimum angle to an accepted one is redrawn.
    let min_cos = (MIN_SPACING * (4.0 * std::f64::consts::PI / n as Real).sqrt()).cos();
    let mut raw: Vec<Point> = Vec::with_capacity(n);
    while raw.len() < n {
        let p = unit_point(&mut rng);
        if raw.iter().all(|q| q.coords.dot(&p) < min_cos) {
            raw.push(Point::from(p));
        }
    }
    let (poly, frame) = ConvexPolyhedron::from_points(&raw)
        .map_err(|e| format!("shape {index}: hull of {n} points: {e}"))?;
    let volume = poly.mass_properties().volume;
    let target = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let scale = (target / volume).cbrt();
    // Principal-frame vertices turned back to the input axes (centroid at the origin), then scaled.
    Ok(poly
        .vertices()
        .iter()
        .map(|v| Point::from(frame.rotation * v.coords * scale))
        .collect())
}

/// The polyhedra at the spheres' centres, before any overlap is removed.
pub fn initial_bodies(spheres: &[SphereRow]) -> Result<Vec<BedBody>, String> {
    spheres
        .iter()
        .enumerate()
        .map(|(k, s)| {
            Ok(BedBody {
                id: s.id.clone(),
                radius: s.radius,
                points: shape_points(k, s.radius)?,
                position: s.position,
                orientation: Rotation::identity(),
            })
        })
        .collect()
}

/// Reads the sphere bed.
pub fn read_spheres(path: &Path) -> Result<Vec<SphereRow>, String> {
    read_sphere_table(path).map_err(|e| e.to_string())
}

/// A body's shape in its principal frame and the pose of that frame in the world.
pub struct Placed {
    pub poly: ConvexPolyhedron,
    /// Principal frame in the body's own frame.
    pub frame: Pose,
}

/// Builds the principal-frame shapes of the bodies.
pub fn place(bodies: &[BedBody]) -> Result<Vec<Placed>, String> {
    bodies
        .iter()
        .map(|b| {
            let (poly, frame) = ConvexPolyhedron::from_points(&b.points)
                .map_err(|e| format!("body {}: {e}", b.id))?;
            Ok(Placed { poly, frame })
        })
        .collect()
}

/// World pose of the principal frame of body `b`.
pub fn world_pose(b: &BedBody, p: &Placed) -> Pose {
    let own = Pose::from_parts(b.position.into(), b.orientation);
    own * p.frame
}

/// An axis-aligned wall: the solid half-space behind the plane through `point` with inward normal `normal`.
#[derive(Clone, Copy, Debug)]
pub struct BoxWall {
    pub point: Vector,
    pub normal: Vector,
}

/// The walls of the open box of the scene: x and y from 0 to `side`, floor at z = 0.
pub fn box_walls(side: Real) -> Vec<BoxWall> {
    let w = |point: [Real; 3], normal: [Real; 3]| BoxWall {
        point: Vector::from(point),
        normal: Vector::from(normal),
    };
    vec![
        w([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        w([side, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        w([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        w([0.0, side, 0.0], [0.0, -1.0, 0.0]),
        w([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    ]
}

/// Depth of body `b` behind `wall` (m; ≤ 0 when clear).
pub fn wall_depth(b: &BedBody, wall: &BoxWall) -> Real {
    b.points
        .iter()
        .map(|p| -(b.orientation * p.coords + b.position - wall.point).dot(&wall.normal))
        .fold(Real::NEG_INFINITY, Real::max)
}

/// Pairs whose bounding spheres (circumradius about the centroid) are within `margin` of each other.
pub fn candidate_pairs(bodies: &[BedBody], margin: Real) -> Vec<(usize, usize)> {
    let radii: Vec<Real> = bodies
        .iter()
        .map(|b| {
            b.points
                .iter()
                .map(|p| p.coords.norm())
                .fold(0.0, Real::max)
        })
        .collect();
    // Sort by x and sweep: O(n log n + pairs).
    let mut order: Vec<usize> = (0..bodies.len()).collect();
    order.sort_by(|&a, &b| bodies[a].position.x.total_cmp(&bodies[b].position.x));
    let r_max = radii.iter().copied().fold(0.0, Real::max);
    let mut pairs = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if bodies[j].position.x - bodies[i].position.x > 2.0 * r_max + margin {
                break;
            }
            if (bodies[j].position - bodies[i].position).norm() <= radii[i] + radii[j] + margin {
                pairs.push((i.min(j), i.max(j)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// What [`push_apart`] did.
#[derive(Clone, Copy, Debug, Default)]
pub struct PushApart {
    pub sweeps: usize,
    /// Largest body–body Minkowski overlap before the first sweep (m).
    pub initial_max_overlap: Real,
    /// Largest wall overlap before the first sweep (m).
    pub initial_max_wall_overlap: Real,
    /// Overlapping body pairs before the first sweep.
    pub initial_overlapping_pairs: usize,
    /// Largest displacement of a centroid from its sphere's centre (m).
    pub max_displacement: Real,
    /// Largest remaining body–body overlap after the last sweep (m; 0 when none overlaps).
    pub final_max_overlap: Real,
}

/// Removes the overlaps by moving centroids (see the module docs): sweeps until no pair and no wall
/// overlaps, at most `max_sweeps`. Separated pairs end at least `gap` (m) apart along n_M.
pub fn push_apart(
    bodies: &mut [BedBody],
    walls: &[BoxWall],
    gap: Real,
    max_sweeps: usize,
    mut on_sweep: impl FnMut(usize, usize, Real),
) -> Result<PushApart, String> {
    let placed = place(bodies)?;
    let start: Vec<Vector> = bodies.iter().map(|b| b.position).collect();
    let mut out = PushApart::default();
    let mut pairs = candidate_pairs(bodies, 4.0 * gap);
    let mut moved_since_pairs: Real = 0.0;
    for sweep in 0..=max_sweeps {
        let (mut worst, mut worst_wall, mut overlapping) = (0.0_f64, 0.0_f64, 0usize);
        for &(i, j) in &pairs {
            let g = query_polyhedra(
                &world_pose(&bodies[i], &placed[i]),
                &placed[i].poly,
                &world_pose(&bodies[j], &placed[j]),
                &placed[j].poly,
            );
            if g.kind == ContactKind::Overlap {
                overlapping += 1;
                worst = worst.max(g.depth);
                if sweep < max_sweeps {
                    let shift = 0.5 * (g.depth + gap) * g.normal;
                    bodies[i].position -= shift;
                    bodies[j].position += shift;
                    moved_since_pairs = moved_since_pairs.max(shift.norm());
                }
            }
        }
        for b in bodies.iter_mut() {
            for w in walls {
                let d = wall_depth(b, w);
                if d > -gap {
                    worst_wall = worst_wall.max(d);
                    if sweep < max_sweeps {
                        b.position += (d + gap) * w.normal;
                    }
                }
            }
        }
        if sweep == 0 {
            out.initial_max_overlap = worst;
            out.initial_max_wall_overlap = worst_wall;
            out.initial_overlapping_pairs = overlapping;
        }
        out.sweeps = sweep;
        out.final_max_overlap = worst;
        on_sweep(sweep, overlapping, worst);
        if overlapping == 0 && worst_wall <= 0.0 {
            break;
        }
        // Bodies moved: refresh the candidates once the accumulated motion could matter.
        if moved_since_pairs > gap {
            pairs = candidate_pairs(bodies, 4.0 * gap);
            moved_since_pairs = 0.0;
        }
    }
    out.max_displacement = bodies
        .iter()
        .zip(&start)
        .map(|(b, s)| (b.position - s).norm())
        .fold(0.0, Real::max);
    Ok(out)
}

/// Writes `v` for TOML with full precision (shortest round trip).
fn num(v: Real) -> String {
    let s = format!("{v:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn vec3(v: &Vector) -> String {
    format!("[{}, {}, {}]", num(v.x), num(v.y), num(v.z))
}

/// The `[[shape]]` and `[[body]]` tables of the bed (material `bed`, bodies named `bed<id>`).
pub fn bed_tables(bodies: &[BedBody]) -> String {
    let mut s = String::new();
    for b in bodies {
        let _ = writeln!(
            s,
            "\n[[shape]]\nname = \"p{}\"\nkind = \"polyhedron\"\npoints = [",
            b.id
        );
        for p in &b.points {
            let _ = writeln!(s, "  {},", vec3(&p.coords));
        }
        let q = b.orientation.quaternion();
        let _ = writeln!(
            s,
            "]\n\n[[body]]\nname = \"bed{}\"\nshape = \"p{}\"\nmaterial = \"bed\"\nposition = {}\norientation = [{}, {}, {}, {}]",
            b.id,
            b.id,
            vec3(&b.position),
            num(q.w),
            num(q.i),
            num(q.j),
            num(q.k)
        );
    }
    s
}

/// Highest point of the bed (m): max over vertices of z.
pub fn bed_top(bodies: &[BedBody]) -> Real {
    bodies
        .iter()
        .flat_map(|b| {
            b.points
                .iter()
                .map(move |p| (b.orientation * p.coords + b.position).z)
        })
        .fold(Real::NEG_INFINITY, Real::max)
}

/// The settled state of the bed: `id,x,y,z,qw,qx,qy,qz,radius` per body (centroid, orientation of the
/// body's own frame, radius of the sphere it replaced), `#` provenance lines first.
pub fn write_state(bodies: &[BedBody], header: &[String]) -> String {
    let mut s = String::new();
    for h in header {
        let _ = writeln!(s, "# {h}");
    }
    s.push_str("id,x,y,z,qw,qx,qy,qz,radius\n");
    for b in bodies {
        let q = b.orientation.quaternion();
        let _ = writeln!(
            s,
            "{},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            b.id, b.position.x, b.position.y, b.position.z, q.w, q.i, q.j, q.k, b.radius
        );
    }
    s
}

/// Rebuilds the settled bed from the sphere file (ids, radii, shape seeds) and the state file written by
/// [`write_state`]; the rows must match the spheres one for one.
pub fn bed_bodies(spheres: &[SphereRow], state_text: &str) -> Result<Vec<BedBody>, String> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(state_text.as_bytes());
    let mut bodies = initial_bodies(spheres)?;
    let mut rows = 0;
    for (k, record) in reader.records().enumerate() {
        let record = record.map_err(|e| format!("state file: {e}"))?;
        let b = bodies.get_mut(k).ok_or_else(|| {
            format!(
                "state file: row {} beyond the {} spheres",
                k + 1,
                spheres.len()
            )
        })?;
        let f = |c: usize| -> Result<Real, String> {
            record
                .get(c)
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| format!("state file: row {}: column {c} is not a number", k + 1))
        };
        if record.get(0) != Some(b.id.as_str()) {
            return Err(format!(
                "state file: row {} has id {:?}, the sphere file {:?}",
                k + 1,
                record.get(0),
                b.id
            ));
        }
        if (f(8)? - b.radius).abs() > 1e-12 * b.radius {
            return Err(format!(
                "state file: row {}: radius {} differs from the sphere file's {}",
                k + 1,
                f(8)?,
                b.radius
            ));
        }
        b.position = Vector::new(f(1)?, f(2)?, f(3)?);
        b.orientation =
            Rotation::from_quaternion(nalgebra::Quaternion::new(f(4)?, f(5)?, f(6)?, f(7)?));
        rows += 1;
    }
    if rows != spheres.len() {
        return Err(format!(
            "state file: {rows} rows for {} spheres",
            spheres.len()
        ));
    }
    Ok(bodies)
}

/// The scene of the polyhedral bed from the sphere scene `template` (the text of
/// `scenes/sphere_bed_*.toml`): the same simulation settings, materials, laws, box and projectile, the
/// `[[body_file]]` of spheres replaced by the polyhedra. `projectile_z` moves the projectile's centre to
/// that height; `None` removes the projectile (the settling run). `simulation` sets keys of the
/// `[simulation]` table (e.g. `end_time`, `time_step`, `viscous_damping_rate`).
pub fn scene_text(
    template: &str,
    bodies: &[BedBody],
    projectile_z: Option<Real>,
    simulation: &[(&str, Real)],
    header: &str,
) -> Result<String, String> {
    let mut table: toml::Table =
        toml::from_str(template).map_err(|e| format!("scene template: {e}"))?;
    if table.remove("body_file").is_none() {
        return Err("scene template: no [[body_file]] of spheres to replace".into());
    }
    let sim = table
        .get_mut("simulation")
        .and_then(toml::Value::as_table_mut)
        .ok_or("scene template: no [simulation]")?;
    for (key, value) in simulation {
        sim.insert((*key).into(), toml::Value::Float(*value));
    }
    let body_list = table
        .get_mut("body")
        .and_then(toml::Value::as_array_mut)
        .ok_or("scene template: no [[body]]")?;
    let is_projectile =
        |v: &toml::Value| v.get("name").and_then(toml::Value::as_str) == Some("projectile");
    match projectile_z {
        Some(z) => {
            let p = body_list
                .iter_mut()
                .find(|v| is_projectile(v))
                .ok_or("scene template: no body named 'projectile'")?;
            let pos = p
                .get_mut("position")
                .and_then(toml::Value::as_array_mut)
                .filter(|a| a.len() == 3)
                .ok_or("scene template: the projectile has no position")?;
            pos[2] = toml::Value::Float(z);
        }
        None => {
            body_list.retain(|v| !is_projectile(v));
            if body_list.is_empty() {
                table.remove("body");
            }
        }
    }
    let text = toml::to_string(&table).map_err(|e| format!("scene template: {e}"))?;
    Ok(format!("{header}{text}{}", bed_tables(bodies)))
}
