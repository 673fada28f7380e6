//! Packing (paper section 4.1, Fig. 4): the loose Voronoi sample falls under gravity into a box container,
//! is compacted by the top wall moving down to the layer height, and is held; the packed bed is saved.
//! The run itself is [`crate::packing_run`]; this module holds the world, its time step and the bed files.
//!
//! # Container
//! Plane walls (half-spaces) at the layer's faces: floor z = 0, sides y = 0 and y = W, top (starts at the
//! generation height), and the left (x = 0) and right (x = L) faces. The left and right walls are added last
//! so that the penetration run can drop them (the projectile enters through the left face and leaves through
//! the right one) without renumbering the other walls' contact-store keys.
//!
//! # Stages
//! 0. Pre-collapse (when `collapse_gap` is set, [`super::collapse`], done on the rocks before the world is
//!    built): every rock moved straight down until it nearly touches a rock or the floor.
//! 1. Deposition: gravity with a global mass-proportional viscous damping α (a numerical device that removes
//!    the kinetic energy of the fall; accounted in the energy ledger as viscous dissipation, and switched off
//!    in the penetration run), until every rock is slower than `settle_speed` (and, when
//!    `settle_kinetic_fraction` is set, the kinetic energy is below that fraction of Σ m g d̄), at least a
//!    minimum time and at most `max_deposition_time`. The minimum time is the free-fall time of the
//!    generation height for a drop from the loose sample, and for a pre-collapsed bed the free-fall time
//!    over the sum of the gaps under a rock at the bed's top, n g_c with n = top / d̄ rock layers and g_c the
//!    collapse gap (the time for the top of the stack to close every gap under it: before that the bed is
//!    still starting to move, and its speeds say nothing about rest).
//! 2. Compaction: if the bed stands above the layer height H, the top wall is placed on the bed and moves down
//!    at `compaction_speed` until it reaches H, slowed by a servo as its contact force F approaches the cap
//!    F_cap = `compaction_pressure` × L W (speed × max(0, 1 − F/F_cap)). If it stalls (speed below [`STALL_FRACTION`]) for
//!    `hold_time`, compaction ends above H and the report says so. Without the cap a wall driven to a fixed
//!    height through a jammed bed forces overlaps of several per cent of the rock size, and at Δt = t_c/20 the
//!    ledger then fails to close by many times the wall's work (measured: 24× the rocks' initial potential
//!    energy on a 50-rock bed at 0.5 m/s; 1.1× at t_c/60).
//! 3. Hold: the top wall stops; the bed relaxes for `hold_time`.
//! 4. Restore (only with `packing_density_scale` = s): stages 1–3 ran with every rock's density s ρ (mass and
//!    inertia × s, velocities kept at the start); the true masses and inertias are now set again (recomputed
//!    from the shape and ρ, so they are the bits of an unscaled bed; the angular momentum is divided by s so
//!    that the angular velocity is kept), the change of the kinetic and gravitational energy is booked in the
//!    ledger as external work, and the bed runs for `restore_time`: over its first half the density goes
//!    from s ρ down to ρ geometrically (s^(1−τ) ρ, every step at the Δt of its masses), so that the elastic
//!    energy the scaled weights stored is released slowly and damped by the contacts, over its second half at
//!    ρ and the true Δt; meanwhile the top wall backs off (servo upwards at up to `compaction_speed`) while
//!    its force exceeds the one it would carry at the current weights, F σ/s (F at the end of the hold). Why s changes nothing but the time step: dividing the equations of motion by s,
//!    s m ẍ = s m g + F_c(k, x) is m ẍ = m g + F_c(k/s, x) (the restitution damping is set from e and
//!    scales as √(m k) with the pair, the viscous damping is mass-proportional, the compaction cap is scaled
//!    by s), so the scaled packing is the one of a bed of true mass with the stiffness k/s: Δt ∝ √(m/k) grows
//!    by √s, the overlaps under the weights and the wall by s, the impact overlaps by √s; the fall and the
//!    settling keep their physical time. Restoring the mass puts the overlaps back towards 1/s of their
//!    scaled values, which is what the restore stage lets happen: the bed expands (measured at 290 mm: the top
//!    wall rises 22–29 mm at s = 5.5, 61 mm at s = 16; `reports/rockfill_study.md`).
//!
//! # Time step
//! Δt = t_c / N with t_c = π √(m*/k_n) for the lightest rock pair (m* = m_min/2, the shortest contact of the
//! linear law) and N = `steps_per_contact`; it is checked against the stability limit of
//! [`polydem::scene::time_step::contact_time_and_limit`]. Both are computed from the world's masses, so with
//! `packing_density_scale` = s the packing's Δt is √s times the unscaled one and the restore stage's Δt is
//! the unscaled one.
//!
//! # Bed file
//! Two CSV files: `bed_shapes.csv` (`shape,vertex,x,y,z`: every rock's vertices in its principal frame, m)
//! and `bed_rocks.csv` (`rock,shape,x,y,z,qw,qx,qy,qz,vx,vy,vz,lx,ly,lz`: centre of mass, body → world
//! quaternion, velocity, world angular momentum), plus `bed_walls.csv` (`wall,nx,ny,nz,px,py,pz`: outward
//! normal and a point of each wall). Values are written in the shortest round-trip form, so a reload
//! reproduces the state to the last bit of the stored numbers (the hull is rebuilt from the stored vertices;
//! its principal frame is composed with the stored pose).

use std::io::Write;
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use super::collapse::CollapseReport;
use super::config::{ConfigError, ExperimentConfig};
use super::grading::Rock;
use super::limits::LimitError;
use polydem::dynamics::{BodyError, PrincipalInertia, RigidBody};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::scene::time_step::{contact_time_and_limit, PairEstimate};
use polydem::shape::{ConvexPolyhedron, Plane, Shape, ShapeError};
use polydem::world::{MaterialTable, StepCounters, StepError, Wall, World, WorldError};

/// Material ids of the experiment's world.
pub const ROCK: u32 = 0;
pub const STEEL: u32 = 1;
pub const WALL: u32 = 2;
/// Number of walls that stay for the penetration run (floor, two sides, top); the left and right walls follow.
pub const KEPT_WALLS: usize = 4;

/// Why packing (or reading/writing a bed) failed.
#[derive(Debug, thiserror::Error)]
pub enum PackingError {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    World(#[from] WorldError),
    #[error(transparent)]
    Body(#[from] BodyError),
    #[error(transparent)]
    Shape(#[from] ShapeError),
    #[error(transparent)]
    Step(#[from] StepError),
    #[error("no rocks to pack")]
    NoRocks,
    #[error(
        "time step {dt} s exceeds the stability limit {limit} s (steps_per_contact too small)"
    )]
    UnstableStep { dt: Real, limit: Real },
    #[error("bed file {path}: {message}")]
    BedFile { path: String, message: String },
    #[error(transparent)]
    Limit(#[from] LimitError),
    /// The run's [`super::stop::StopCheck`] asked it to stop (before a step: the world is at a step boundary).
    #[error("packing interrupted at t = {time} s")]
    Interrupted { time: Real },
}

/// The world of the experiment: materials (rock, steel, wall) with Table 1's laws, gravity −9.81 e_z.
pub fn empty_world(config: &ExperimentConfig, skin: Real) -> Result<World, PackingError> {
    let models = config.contact_models()?;
    let mut materials = MaterialTable::default();
    let rock = materials.add_material("rock");
    let steel = materials.add_material("steel");
    let wall = materials.add_material("wall");
    materials.set_model(rock, rock, models.rocks);
    materials.set_model(rock, wall, models.rocks);
    materials.set_model(rock, steel, models.projectile);
    materials.set_model(steel, wall, models.rocks);
    materials.set_model(steel, steel, models.rocks);
    Ok(World::new(Vector::new(0.0, 0.0, -9.81), materials, skin))
}

/// A dynamic body of density `density` for a polyhedron placed at `pose` (principal frame → world).
pub fn body_for(
    shape: &ConvexPolyhedron,
    pose: &Pose,
    density: Real,
) -> Result<RigidBody, BodyError> {
    let mp = shape.mass_properties();
    let mut body = RigidBody::new_dynamic(
        Point::from(pose.translation.vector),
        mp.mass(density),
        PrincipalInertia::new(mp.principal_inertia(density))?,
    )?;
    body.orientation = pose.rotation;
    Ok(body)
}

fn wall(name: &str, normal: Vector, point: Point) -> Result<Wall, PackingError> {
    Ok(Wall {
        name: name.to_owned(),
        plane: Plane::new(normal, normal.dot(&point.coords))?,
        pose: Pose::identity(),
        velocity: Vector::zeros(),
        material: WALL,
    })
}

/// The compaction stalls when the servo holds the top wall below this fraction of its speed: a quarter, because
/// the servo's approach to the force cap is asymptotic and a lower threshold spends most of the compaction
/// creeping (measured on a 50-rock bed: 5 % took 16 000 steps).
pub const STALL_FRACTION: Real = 0.25;

/// Index of the top wall.
pub const TOP_WALL: usize = 3;

/// Adds the six walls of the container of length L, width W, with the top at `top`.
pub fn add_container(
    world: &mut World,
    length: Real,
    width: Real,
    top: Real,
) -> Result<(), PackingError> {
    let walls = [
        wall("floor", Vector::z(), Point::origin())?,
        wall("side y=0", Vector::y(), Point::origin())?,
        wall("side y=W", -Vector::y(), Point::new(0.0, width, 0.0))?,
        wall("top", -Vector::z(), Point::new(0.0, 0.0, top))?,
        wall("left x=0", Vector::x(), Point::origin())?,
        wall("right x=L", -Vector::x(), Point::new(length, 0.0, 0.0))?,
    ];
    for w in walls {
        world.add_wall(w)?;
    }
    Ok(())
}

/// Height of the top wall (m).
pub fn top_wall_height(world: &World) -> Real {
    let w = &world.walls()[TOP_WALL];
    // The wall plane passes through pose * (offset n); its height is that point's z.
    (w.pose * Point::from(w.plane.normal() * w.plane.offset())).z
}

/// Highest point of any rock (m).
pub fn bed_top(world: &World) -> Real {
    (0..world.bodies().len())
        .filter(|&i| world.bodies()[i].is_dynamic())
        .map(|i| match world.shape(i) {
            Shape::Polyhedron(p) => p.aabb(&world.pose(i)).maxs.z,
            _ => world.bodies()[i].position.z + world.radii()[i],
        })
        .fold(Real::NEG_INFINITY, Real::max)
}

/// Largest rock speed (m/s).
pub fn max_speed(world: &World) -> Real {
    world
        .bodies()
        .iter()
        .filter(|b| b.is_dynamic())
        .map(|b| b.velocity.norm())
        .fold(0.0, Real::max)
}

/// The Verlet skin of the broad phase: 5 % of the mean rock size (rebuilds are cheap next to polyhedral
/// narrow-phase queries, so a thin skin that keeps the candidate list short pays).
pub fn skin_for(mean_size: Real) -> Real {
    0.05 * mean_size
}

/// Δt and the shortest contact time for rocks of the lightest mass `m_min` (see the module docs), with
/// N = `steps_per_contact` (the penetration's step).
pub fn rock_time_step(
    config: &ExperimentConfig,
    world: &World,
) -> Result<(Real, Real), PackingError> {
    rock_time_step_with(config, world, config.packing.steps_per_contact)
}

/// The packing's Δt may not exceed this fraction of the stability limit 2/ω_max (see
/// [`polydem::scene::time_step`]): the limit is a bound at the edge of stability, and the packing keeps a margin.
pub const PACKING_LIMIT_FRACTION: Real = 0.8;

/// The packing's Δt: t_c,min / `steps_per_contact`, or, when `packing_steps_per_contact` = N is given,
/// min(t_c,min / N, [`PACKING_LIMIT_FRACTION`] × the stability limit) (the limit of the most elongated rock
/// binds at N ≈ 12 for 290 mm rocks: seed 2 of the quick variant has 2/ω_max = t_c/11.7).
pub fn packing_time_step(
    config: &ExperimentConfig,
    world: &World,
) -> Result<(Real, Real), PackingError> {
    let p = &config.packing;
    match p.packing_steps_per_contact {
        None => rock_time_step(config, world),
        Some(n) => {
            // The limit does not depend on N; t_c / 1e6 is always stable.
            let (_, t_c, limit) = time_step_and_limit(config, world, 1e6)?;
            Ok(((t_c / n).min(PACKING_LIMIT_FRACTION * limit), t_c))
        }
    }
}

/// Δt = t_c,min / `steps_per_contact` and t_c,min, checked against the stability limit.
pub fn rock_time_step_with(
    config: &ExperimentConfig,
    world: &World,
    steps_per_contact: Real,
) -> Result<(Real, Real), PackingError> {
    let (dt, t_c, limit) = time_step_and_limit(config, world, steps_per_contact)?;
    if dt > limit {
        return Err(PackingError::UnstableStep { dt, limit });
    }
    Ok((dt, t_c))
}

/// (t_c,min / `steps_per_contact`, t_c,min, stability limit).
pub fn time_step_and_limit(
    config: &ExperimentConfig,
    world: &World,
    steps_per_contact: Real,
) -> Result<(Real, Real, Real), PackingError> {
    let models = config.contact_models()?;
    let m_min = world
        .bodies()
        .iter()
        .filter(|b| b.is_dynamic())
        .map(|b| b.mass)
        .fold(Real::INFINITY, Real::min);
    if !m_min.is_finite() {
        return Err(PackingError::NoRocks);
    }
    let kappa = (0..world.bodies().len())
        .map(|i| {
            let b = &world.bodies()[i];
            1.0 + b.mass * world.radii()[i].powi(2) / b.inertia.0.min()
        })
        .fold(1.0, Real::max);
    let pairs = [
        PairEstimate {
            model: models.rocks,
            effective_mass: 0.5 * m_min,
        },
        PairEstimate {
            model: models.rocks,
            effective_mass: m_min,
        },
    ];
    let (t_c, limit) =
        contact_time_and_limit(&pairs, kappa, None).map_err(|_| PackingError::NoRocks)?;
    Ok((t_c / steps_per_contact, t_c, limit))
}

/// What packing did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PackingReport {
    pub rocks: usize,
    pub dt: Real,
    pub contact_time: Real,
    pub deposition_steps: u64,
    pub compaction_steps: u64,
    pub hold_steps: u64,
    /// Simulated time of each stage (s).
    pub deposition_time: Real,
    pub compaction_time: Real,
    /// Whether compaction ended because the wall force reached the cap before the target height.
    pub compaction_stalled: bool,
    /// Bed top after deposition and at the end (m); the top wall at the end (m).
    pub deposited_top: Real,
    pub final_top: Real,
    pub top_wall: Real,
    /// Σ V_rock / (L W h) with h the final bed top.
    pub solid_fraction: Real,
    /// Largest rock speed at the end (m/s).
    pub final_max_speed: Real,
    /// Largest overlap / particle size seen.
    pub max_overlap_ratio: Real,
    /// Energy-ledger balance after deposition, after compaction and at the end, over the initial potential
    /// energy of the rocks relative to the floor.
    pub ledger_balance_relative: [Real; 3],
    pub wall_time: Duration,
    /// The step's stage timers and counters summed over deposition, compaction, hold and restore.
    pub counters: [StepCounters; 4],
    /// `packing_density_scale` (1 without it).
    pub density_scale: Real,
    /// The restore stage (density scaling only): its Δt (s, the unscaled packing Δt), steps, the top wall's
    /// rise (m) and its force before and after (N).
    pub restore_dt: Real,
    pub restore_steps: u64,
    pub restore_wall_rise: Real,
    pub restore_wall_force: [Real; 2],
    /// Largest and mean overlap of the rock–rock and rock–wall contacts of the bed at the end of the hold
    /// (scaled masses) and at the end, over the mean rock size.
    pub bed_overlap_after_hold: [Real; 2],
    pub bed_overlap_final: [Real; 2],
    /// The pre-collapse, when the configuration asks for one (set by the caller that collapsed the rocks).
    pub collapse: Option<CollapseReport>,
    /// The bed every [`TRACE_EVERY`] steps (written as `packing_trace.csv`).
    pub trace: Vec<PackingSample>,
}

/// Names of the packing stages, as in the trace and the summary.
pub const STAGE_NAMES: [&str; 4] = ["deposition", "compaction", "hold", "restore"];

/// Steps between two rows of [`PackingReport::trace`] (and between two settle checks).
pub const TRACE_EVERY: u64 = 100;

/// One row of the packing trace.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PackingSample {
    /// 0 deposition, 1 compaction, 2 hold, 3 restore.
    pub stage: usize,
    pub step: u64,
    /// Simulated time (s).
    pub time: Real,
    /// Largest rock speed (m/s).
    pub max_speed: Real,
    /// Translational + rotational kinetic energy of the rocks (J).
    pub kinetic_energy: Real,
    /// Kinetic energy / Σ m g d̄.
    pub kinetic_fraction: Real,
    /// Highest rock point and top wall (m).
    pub bed_top: Real,
    pub top_wall: Real,
    /// z component of the top wall's contact force, as the compaction servo reads it (N).
    pub wall_force: Real,
}

impl PackingSample {
    pub const CSV_HEADER: &'static str =
        "stage,step,time,max_speed,kinetic_energy,kinetic_fraction,bed_top,top_wall,wall_force";

    pub fn csv_row(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{}",
            STAGE_NAMES[self.stage.min(3)],
            self.step,
            self.time,
            self.max_speed,
            self.kinetic_energy,
            self.kinetic_fraction,
            self.bed_top,
            self.top_wall,
            self.wall_force
        )
    }
}

/// Writes the packing trace as CSV.
pub fn write_packing_trace(path: &Path, trace: &[PackingSample]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "{}", PackingSample::CSV_HEADER)?;
    for row in trace {
        writeln!(out, "{}", row.csv_row())?;
    }
    out.flush()
}

/// Builds the loose world from `rocks` (container top at `top`).
pub fn loose_world(
    config: &ExperimentConfig,
    rocks: &[Rock],
    top: Real,
) -> Result<World, PackingError> {
    if rocks.is_empty() {
        return Err(PackingError::NoRocks);
    }
    let mut world = empty_world(config, skin_for(config.rock.mean_size))?;
    add_container(&mut world, config.layer.length, config.layer.width, top)?;
    for (k, rock) in rocks.iter().enumerate() {
        let shape = world.add_shape(Shape::Polyhedron(Arc::clone(&rock.shape)));
        let body = body_for(&rock.shape, &rock.pose, config.rock.density)?;
        world.add_body(&format!("rock{k}"), shape, ROCK, body)?;
    }
    Ok(world)
}

/// Sets every dynamic polyhedral body's mass and principal inertia to those of its shape at `density`
/// (recomputed from the shape, so the values are the bits [`body_for`] gives), keeping its velocity and its
/// angular velocity (the angular momentum is scaled with the inertia). Returns the change of the
/// mechanical energy (J: kinetic and gravitational change, the elastic energy does not depend on the mass).
pub fn set_rock_density(world: &mut World, density: Real) -> Result<Real, PackingError> {
    let before = world.energy().mechanical();
    for i in 0..world.bodies().len() {
        if !world.bodies()[i].is_dynamic() {
            continue;
        }
        let Shape::Polyhedron(shape) = world.shape(i) else {
            continue;
        };
        let mp = shape.mass_properties();
        let (mass, inertia) = (
            mp.mass(density),
            PrincipalInertia::new(mp.principal_inertia(density))?,
        );
        world.edit_body(i, |b| {
            let ratio = mass / b.mass;
            b.mass = mass;
            b.inertia = inertia;
            b.angular_momentum *= ratio;
        })?;
    }
    Ok(world.energy().mechanical() - before)
}

/// Largest and mean overlap (depth) of the active contacts in the store, over `size`.
pub fn bed_overlap(world: &World, size: Real) -> [Real; 2] {
    let depths: Vec<Real> = world
        .contacts()
        .states()
        .iter()
        .filter(|c| c.is_active())
        .map(|c| c.geometry.depth)
        .collect();
    if depths.is_empty() {
        return [0.0, 0.0];
    }
    let max = depths.iter().copied().fold(0.0, Real::max);
    let mean = depths.iter().sum::<Real>() / depths.len() as Real;
    [max / size, mean / size]
}

/// Cundall's local (non-viscous) damping of one vector quantity over a step: every component of `value`
/// (a velocity, or an angular momentum) moves towards zero by α |load_i| `scale` (the load's impulse over the
/// step divided by what turns impulse into `value`: Δt/m for a velocity, Δt for an angular momentum), against
/// the sign of the matching component of `rate` (the velocity, or the angular velocity), and never past zero.
/// A component whose `value` and `rate` differ in sign is left alone. The damping force is thus α times
/// the unbalanced force, opposed to the motion: it vanishes for a body at rest under balanced loads and
/// whatever the body's speed when no force acts, which is why it removes the energy of rattling without
/// slowing a steady fall more than α (the deposition applies it only to rocks in contact, so a rock in free
/// flight is not slowed at all).
pub fn local_damping(
    value: &Vector,
    rate: &Vector,
    load: &Vector,
    alpha: Real,
    scale: Real,
) -> Vector {
    Vector::from_fn(|i, _| {
        let (v, w) = (value[i], rate[i]);
        if v == 0.0 || w == 0.0 || v.signum() != w.signum() {
            return v;
        }
        let cut = (alpha * load[i].abs() * scale).min(v.abs());
        v - v.signum() * cut
    })
}

/// Applies [`local_damping`] to every dynamic rock that carries a contact load (translation with the unbalanced
/// force F + m g, rotation with the contact torque) and returns the kinetic energy it removed (J, ≥ 0: a
/// change that would raise a body's kinetic energy is not applied).
pub fn apply_local_damping(world: &mut World, alpha: Real, dt: Real) -> Real {
    let gravity = world.gravity();
    let mut removed = 0.0;
    for i in 0..world.body_count() {
        if !world.body(i).is_dynamic() {
            continue;
        }
        let loads = world.loads();
        let (force, torque) = match (loads.forces().get(i), loads.torques().get(i)) {
            (Some(f), Some(t)) => (*f, *t),
            _ => continue,
        };
        if force == Vector::zeros() && torque == Vector::zeros() {
            continue;
        }
        let damp = |b: &mut RigidBody| -> Real {
            let before = b.translational_kinetic_energy() + b.rotational_kinetic_energy();
            let (v, l) = (b.velocity, b.angular_momentum);
            let unbalanced = force + b.mass * gravity;
            b.velocity = local_damping(&v, &v, &unbalanced, alpha, dt / b.mass);
            let omega = b.angular_velocity();
            b.angular_momentum = local_damping(&l, &omega, &torque, alpha, dt);
            let after = b.translational_kinetic_energy() + b.rotational_kinetic_energy();
            if after > before {
                b.velocity = v;
                b.angular_momentum = l;
                0.0
            } else {
                before - after
            }
        };
        // The index is a body's: the edit cannot fail.
        removed += world.edit_body(i, damp).unwrap_or(0.0);
    }
    removed
}

fn bed_error(path: &Path, message: impl Into<String>) -> PackingError {
    PackingError::BedFile {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// Writes the bed files into `dir` (see the module docs).
pub fn save_bed(world: &World, dir: &Path) -> Result<(), PackingError> {
    let io = |e: std::io::Error| bed_error(dir, e.to_string());
    std::fs::create_dir_all(dir).map_err(io)?;
    let mut shapes =
        std::io::BufWriter::new(std::fs::File::create(dir.join("bed_shapes.csv")).map_err(io)?);
    writeln!(shapes, "shape,vertex,x,y,z").map_err(io)?;
    for (s, shape) in world.shapes().iter().enumerate() {
        if let Shape::Polyhedron(p) = shape {
            for (v, x) in p.vertices().iter().enumerate() {
                writeln!(shapes, "{s},{v},{},{},{}", x.x, x.y, x.z).map_err(io)?;
            }
        }
    }
    let mut rocks =
        std::io::BufWriter::new(std::fs::File::create(dir.join("bed_rocks.csv")).map_err(io)?);
    writeln!(rocks, "rock,shape,x,y,z,qw,qx,qy,qz,vx,vy,vz,lx,ly,lz").map_err(io)?;
    for (i, b) in world.bodies().iter().enumerate() {
        let (p, q, v, l) = (b.position, b.orientation, b.velocity, b.angular_momentum);
        writeln!(
            rocks,
            "{i},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            world.shape_indices()[i],
            p.x,
            p.y,
            p.z,
            q.w,
            q.i,
            q.j,
            q.k,
            v.x,
            v.y,
            v.z,
            l.x,
            l.y,
            l.z
        )
        .map_err(io)?;
    }
    let mut walls =
        std::io::BufWriter::new(std::fs::File::create(dir.join("bed_walls.csv")).map_err(io)?);
    writeln!(walls, "wall,nx,ny,nz,px,py,pz").map_err(io)?;
    for w in world.walls() {
        let n = w.normal_world();
        let p = w.pose * Point::from(w.plane.normal() * w.plane.offset());
        writeln!(
            walls,
            "{},{},{},{},{},{},{}",
            w.name, n.x, n.y, n.z, p.x, p.y, p.z
        )
        .map_err(io)?;
    }
    Ok(())
}

fn read_rows(path: &Path, columns: usize) -> Result<Vec<Vec<String>>, PackingError> {
    let text = std::fs::read_to_string(path).map_err(|e| bed_error(path, e.to_string()))?;
    let mut rows = Vec::new();
    for (line_no, line) in text.lines().enumerate().skip(1) {
        let fields: Vec<String> = line.split(',').map(str::to_owned).collect();
        if fields.len() != columns {
            return Err(bed_error(
                path,
                format!(
                    "line {}: {} fields, expected {columns}",
                    line_no + 1,
                    fields.len()
                ),
            ));
        }
        rows.push(fields);
    }
    Ok(rows)
}

fn number(path: &Path, row: usize, field: &str) -> Result<Real, PackingError> {
    field
        .parse::<Real>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| {
            bed_error(
                path,
                format!("line {}: '{field}' is not a finite number", row + 2),
            )
        })
}

/// Reads a bed written by [`save_bed`] into a fresh world with the experiment's materials.
pub fn load_bed(config: &ExperimentConfig, dir: &Path) -> Result<World, PackingError> {
    let mut world = empty_world(config, skin_for(config.rock.mean_size))?;
    let path = dir.join("bed_walls.csv");
    for (r, row) in read_rows(&path, 7)?.iter().enumerate() {
        let f: Vec<Real> = row[1..]
            .iter()
            .map(|x| number(&path, r, x))
            .collect::<Result<_, _>>()?;
        world.add_wall(wall(
            &row[0],
            Vector::new(f[0], f[1], f[2]),
            Point::new(f[3], f[4], f[5]),
        )?)?;
    }
    let path = dir.join("bed_shapes.csv");
    let mut vertices: Vec<Vec<Point>> = Vec::new();
    for (r, row) in read_rows(&path, 5)?.iter().enumerate() {
        let s: usize = row[0]
            .parse()
            .map_err(|_| bed_error(&path, format!("line {}: bad shape index", r + 2)))?;
        if s >= vertices.len() {
            vertices.resize(s + 1, Vec::new());
        }
        vertices[s].push(Point::new(
            number(&path, r, &row[2])?,
            number(&path, r, &row[3])?,
            number(&path, r, &row[4])?,
        ));
    }
    let mut rebuilt: Vec<Option<(Arc<ConvexPolyhedron>, Pose)>> = vec![None; vertices.len()];
    let path = dir.join("bed_rocks.csv");
    for (r, row) in read_rows(&path, 15)?.iter().enumerate() {
        let s: usize = row[1]
            .parse()
            .ok()
            .filter(|&s: &usize| s < vertices.len() && !vertices[s].is_empty())
            .ok_or_else(|| {
                bed_error(&path, format!("line {}: unknown shape '{}'", r + 2, row[1]))
            })?;
        let f: Vec<Real> = row[2..]
            .iter()
            .map(|x| number(&path, r, x))
            .collect::<Result<_, _>>()?;
        if rebuilt[s].is_none() {
            let (shape, frame) = ConvexPolyhedron::from_points(&vertices[s])?;
            rebuilt[s] = Some((Arc::new(shape), frame));
        }
        let (shape, frame) = rebuilt[s].clone().expect("built above");
        let q = Rotation::from_quaternion(nalgebra::Quaternion::new(f[3], f[4], f[5], f[6]));
        let stored = Pose::from_parts(Vector::new(f[0], f[1], f[2]).into(), q);
        let pose = stored * frame;
        let mut body = body_for(&shape, &pose, config.rock.density)?;
        body.velocity = Vector::new(f[7], f[8], f[9]);
        body.angular_momentum = Vector::new(f[10], f[11], f[12]);
        let id = world.add_shape(Shape::Polyhedron(shape));
        world.add_body(&format!("rock{r}"), id, ROCK, body)?;
    }
    if world.bodies().is_empty() {
        return Err(PackingError::NoRocks);
    }
    Ok(world)
}
