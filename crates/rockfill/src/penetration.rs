//! The penetration run (paper section 4.2, Figs. 7–8): the projectile, aimed at the centre of the packed bed's
//! left face along +x at 1200 m/s, reaches the face at `arrival_time`; the run continues until its base has
//! left the layer through the right face (exit), it has stopped, or `max_time`.
//!
//! Before the run the left and right container walls are removed (the layer's free faces; the top wall stays
//! where compaction left it, fixed) and the global viscous damping of packing is switched off, so every loss
//! in the ledger is a contact loss. The time step is the packing one or smaller, so that the projectile
//! travels at most `travel_per_step` of a mean rock size per step.
//!
//! # Monitors and files
//! One [`MonitorRow`] per step ([`super::monitors`]). The run hands its state to its outputs through the
//! engine's [`Output`] trait, like `polydem run`: the monitor series (`monitors.csv`, written when the run
//! completes) and, when asked for, the engine's VTK frames of the bed and the projectile
//! ([`PenetrationFiles`]).
//!
//! # Disturbed zone
//! At the end, a rock is disturbed when its displacement since the start of the run exceeds
//! `disturbed_threshold` × the mean size. The zone's width is twice the radial distance from the initial line
//! of flight (the x axis through the aim point) within which 95 % of the disturbed rocks started, given in mean
//! rock sizes (the paper reports an affected range of 6–7 sizes for the 100 mm sample, read off Fig. 7).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use super::config::ExperimentConfig;
use super::limits::{within, LimitError};
pub use super::monitors::MonitorRow;
use super::monitors::{MonitorSeries, ProjectileGauge};
use super::packing::{
    rock_time_step, time_step_and_limit, top_wall_height, PackingError, KEPT_WALLS, STEEL,
};
pub use super::penetration_error::PenetrationError;
use super::projectile::Projectile;
pub use super::stepper::RankFacts;
use super::stepper::{ImpactStepper, LocalStepper};
use super::stop::{self, StopCheck};
use polydem::dynamics::{Motion, RigidBody, ViscousDamping};
use polydem::io::output::{Output, OutputSet, Schedule};
use polydem::io::vtk::{VtkEncoding, VtkWriter};
use polydem::io::vtk_frames::VtkFrames;
use polydem::math::{Point, Pose, Real, Vector};
use polydem::scene::{RunObserver, Simulation, TimeStepInfo};
use polydem::shape::Shape;
use polydem::world::{sleeping, StepCounters, StepParams, World};

/// Displacement thresholds (in mean sizes) at which the disturbed zone is also measured: the paper's
/// "affected range" is read off a picture, with no threshold stated.
pub const DISTURBED_THRESHOLDS: [Real; 5] = [0.01, 0.02, 0.05, 0.1, 0.2];

/// How the run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The base left the layer through the right face.
    Exited,
    /// The projectile stopped (speed below 1 % of the impact speed).
    Stopped,
    /// `max_time` was reached first.
    TimeLimit,
    /// [`PenetrationOptions::max_steps`] steps were run first.
    StepLimit,
}

/// Options of a penetration run beyond the experiment file.
#[derive(Clone, Debug, PartialEq)]
pub struct PenetrationOptions {
    /// The run's Δt is the experiment's Δt divided by this (1 for the experiment; 2, 4, … for a time-step
    /// convergence study).
    pub dt_divisor: Real,
    /// Tip positions x (m): at the first step at which the tip is at or past each, every body's pose is
    /// recorded ([`Snapshot`]); when the list is not empty, the state at the end of the run is recorded too.
    pub snapshot_tip_x: Vec<Real>,
    /// Stop after this many steps, whatever the projectile does (benchmarks and regression pins run a
    /// fixed stretch of the impact); `None` runs to the experiment's own end.
    pub max_steps: Option<u64>,
    /// Shifts the projectile's start (m, world frame): a perturbed initial state, whose spread of results
    /// measures how chaotic the run is (zero for the experiment).
    pub start_offset: Vector,
    /// Asked before each step (of the penetration, and of the packing when the run packs a bed) whether
    /// to stop there; `None` runs to the end.
    pub stop: Option<StopCheck>,
    /// The files the run writes; `None` writes none (the report holds the monitor rows either way).
    pub files: Option<PenetrationFiles>,
    /// Step the impact split over the ranks of the MPI job this process belongs to (MPI initialised by the
    /// caller; every rank runs the experiment with the same inputs; rank 0 writes the files). The monitor
    /// rows and every body's final state are one process's bit for bit; see `distributed` for what is
    /// not distributed. Needs the `mpi` feature ([`PenetrationError::NoMpi`] without).
    pub distributed: bool,
}

/// The files a penetration run writes, through the engine's [`Output`] implementations.
#[derive(Clone, Debug, PartialEq)]
pub struct PenetrationFiles {
    /// The directory they go into (created if missing).
    pub dir: PathBuf,
    /// File name of the monitor series in `dir` (`monitors.csv` for a run of the study).
    pub monitors: String,
    /// VTK frames of the bed and the projectile (`vtk/`, with `.pvd` collections) of the state the run
    /// starts from and of every step whose index is a multiple of this (as `polydem run` schedules
    /// them); `None`: no frames.
    pub vtk_every: Option<u64>,
    /// Encoding of the VTK frames.
    pub vtk_encoding: VtkEncoding,
}

impl PenetrationFiles {
    /// The monitor series `monitors.csv` in `dir`, no VTK frames.
    pub fn monitors_in(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: dir.into(),
            monitors: "monitors.csv".into(),
            vtk_every: None,
            vtk_encoding: VtkEncoding::default(),
        }
    }
}

impl Default for PenetrationOptions {
    fn default() -> Self {
        Self {
            dt_divisor: 1.0,
            snapshot_tip_x: Vec::new(),
            max_steps: None,
            start_offset: Vector::zeros(),
            stop: None,
            files: None,
            distributed: false,
        }
    }
}

/// Every body's pose at one instant of the run (for section pictures).
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// Time since the start of the run (s).
    pub time: Real,
    pub tip: Point,
    pub poses: Vec<Pose>,
}

/// The fluctuation of the penetration resistance R = −F·e₀ while the projectile is in the layer (from the
/// tip entering the left face to the base leaving the right face, or the end of the run).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ResistanceStatistics {
    /// Steps in the interval.
    pub samples: usize,
    /// Mean and standard deviation of R over the steps (N).
    pub mean: Real,
    pub std: Real,
    /// std / mean of the per-step R.
    pub cv: Real,
    /// std / mean of R averaged over consecutive windows of one mean rock size of travel at the impact speed
    /// (removes the step-to-step chatter of single contacts; the paper's curves are of this kind).
    pub cv_window: Real,
    /// Windows in the interval.
    pub windows: usize,
}

impl ResistanceStatistics {
    /// From the monitor rows; `window_steps` steps per window.
    pub fn from_rows(
        rows: &[MonitorRow],
        length: Real,
        projectile_length: Real,
        window_steps: usize,
    ) -> Self {
        let inside: Vec<Real> = rows
            .iter()
            .filter(|r| {
                // The base lies `projectile_length` behind the tip along the axis.
                let base_x = r.tip.x - projectile_length * r.axis_deflection.to_radians().cos();
                r.tip.x >= 0.0 && base_x <= length
            })
            .map(|r| -r.axial_force)
            .collect();
        let (mean, std) = mean_std(&inside);
        let windows: Vec<Real> = inside
            .chunks_exact(window_steps.max(1))
            .map(|w| w.iter().sum::<Real>() / w.len() as Real)
            .collect();
        let (wmean, wstd) = mean_std(&windows);
        Self {
            samples: inside.len(),
            mean,
            std,
            cv: std / mean,
            cv_window: wstd / wmean,
            windows: windows.len(),
        }
    }
}

fn mean_std(x: &[Real]) -> (Real, Real) {
    if x.is_empty() {
        return (Real::NAN, Real::NAN);
    }
    let n = x.len() as Real;
    let mean = x.iter().sum::<Real>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<Real>() / n;
    (mean, var.sqrt())
}

/// What the run measured.
#[derive(Clone, Debug)]
pub struct PenetrationReport {
    pub outcome: Outcome,
    pub rows: Vec<MonitorRow>,
    pub dt: Real,
    pub steps: u64,
    pub rocks: usize,
    pub projectile_mass: Real,
    /// Speed (m/s) and its component along e₀ at the end of the run (the residual velocity on exit).
    pub residual_speed: Real,
    pub residual_axial_velocity: Real,
    /// Time at which the base left the layer (s), if it did.
    pub exit_time: Option<Real>,
    /// Deflection angles at the end and their maxima over the run (degrees).
    pub final_velocity_deflection: Real,
    pub final_axis_deflection: Real,
    pub max_velocity_deflection: Real,
    pub max_axis_deflection: Real,
    /// Largest and mean |axial resistance| while in contact (N).
    pub max_axial_force: Real,
    pub disturbed_rocks: usize,
    /// Width of the disturbed zone (see the module docs), in metres and in mean rock sizes.
    pub disturbed_width: Real,
    pub disturbed_width_sizes: Real,
    /// The zone at each of [`DISTURBED_THRESHOLDS`]: (threshold / mean size, rocks, width in mean sizes).
    pub disturbed_by_threshold: Vec<(Real, usize, Real)>,
    /// Energy-ledger balance at the end / the projectile's initial kinetic energy.
    pub ledger_balance_relative: Real,
    /// Projectile kinetic energy lost (J) and the terms it went to (J).
    pub projectile_energy_loss: Real,
    pub dissipated_damping: Real,
    pub dissipated_friction: Real,
    /// Largest overlap / particle size seen, and the number of steps that reported an overlap above the
    /// engine's warning fraction.
    pub max_overlap_ratio: Real,
    pub steps_with_overlap_warnings: u64,
    /// Fluctuation of the axial resistance while in the layer.
    pub resistance: ResistanceStatistics,
    /// Every body's position at the start of the run, and the snapshots asked for in the options.
    pub start_positions: Vec<Point>,
    pub snapshots: Vec<Snapshot>,
    pub wall_time: Duration,
    /// The step's stage timers and counters summed over the run.
    pub counters: StepCounters,
    /// Rock-steps spent asleep over all rock-steps (0 without sleeping).
    pub asleep_fraction: Real,
    /// This rank's facts, for a run split over MPI ranks ([`PenetrationOptions::distributed`]).
    pub ranks: Option<RankFacts>,
}

/// With `sleeping.penetration`, puts every rock to sleep ([`sleeping::put_to_sleep`]). Removes the left and right walls and adds the projectile with its tip `speed × arrival_time` ahead of
/// the centre of the left face, moving along +x. Returns the projectile's body index.
pub fn add_projectile(
    config: &ExperimentConfig,
    world: &mut World,
    projectile: &Projectile,
) -> Result<usize, PenetrationError> {
    if world.walls().len() != KEPT_WALLS + 2 {
        return Err(PenetrationError::NotABed {
            walls: world.walls().len(),
            expected: KEPT_WALLS + 2,
        });
    }
    if config.sleeping.penetration {
        // The packed bed is at rest: every rock falls asleep against the walls it was packed in, so that
        // removing the left and right walls wakes the rocks they held (see `polydem::world::sleeping`).
        sleeping::put_to_sleep(
            &config.sleeping.params(true),
            world,
            0..world.bodies().len(),
        );
    }
    world.truncate_walls(KEPT_WALLS);
    let height = top_wall_height(world).min(super::packing::bed_top(world));
    let aim = Point::new(0.0, 0.5 * config.layer.width, 0.5 * height);
    let e0 = Vector::x();
    let tip = aim - e0 * (config.impact.speed * config.impact.arrival_time);
    let pose = projectile.pose_with_tip_at(&tip, &e0);
    let mut body = RigidBody::new_dynamic(
        Point::from(pose.translation.vector),
        projectile.mass,
        projectile.inertia,
    )
    .map_err(PackingError::from)?;
    body.orientation = pose.rotation;
    body.velocity = e0 * config.impact.speed;
    body.motion = Motion::Dynamic;
    let shape = world.add_shape(Shape::Polyhedron(projectile.shape.clone()));
    Ok(world.add_body("projectile", shape, STEEL, body)? as usize)
}

/// Runs the impact on a world prepared by [`add_projectile`]. `progress` is called every 100 steps with the
/// latest monitor row.
pub fn penetrate(
    config: &ExperimentConfig,
    world: &mut World,
    projectile: &Projectile,
    index: usize,
    progress: impl FnMut(&MonitorRow),
) -> Result<PenetrationReport, PenetrationError> {
    penetrate_with(
        config,
        world,
        projectile,
        index,
        &PenetrationOptions::default(),
        progress,
    )
}

/// The experiment's Δt of the penetration run (before [`PenetrationOptions::dt_divisor`]).
pub fn penetration_time_step(
    config: &ExperimentConfig,
    world: &World,
) -> Result<Real, PenetrationError> {
    let (dt_rocks, _) = rock_time_step(config, world)?;
    let imp = &config.impact;
    Ok(dt_rocks.min(imp.travel_per_step * config.rock.mean_size / imp.speed))
}

/// [`penetrate`] with options (time-step divisor, pose snapshots, files).
pub fn penetrate_with(
    config: &ExperimentConfig,
    world: &mut World,
    projectile: &Projectile,
    index: usize,
    options: &PenetrationOptions,
    progress: impl FnMut(&MonitorRow),
) -> Result<PenetrationReport, PenetrationError> {
    let start = Instant::now();
    check_distributed(config, options)?;
    let dt = penetration_time_step(config, world)? / options.dt_divisor;
    // A run stopped after `max_steps` (a benchmark's stretch) is bounded by that.
    if options
        .max_steps
        .is_none_or(|m| m > config.limits.max_steps)
    {
        check_penetration_steps(config, dt, false)?;
    }
    let (_, contact_time, stability_limit) =
        time_step_and_limit(config, world, config.packing.steps_per_contact)?;
    let time_step = TimeStepInfo {
        dt,
        derived: true,
        contact_time,
        stability_limit,
    };
    let start_positions: Vec<Point> = world.bodies().iter().map(|b| b.position).collect();
    let kinetic0 = world.bodies()[index].translational_kinetic_energy()
        + world.bodies()[index].rotational_kinetic_energy();
    // The ledger restarts here: removing walls and adding the projectile changed the energy outside it.
    world.reset_ledger();
    let gauge = ProjectileGauge {
        index,
        axis_body: projectile.axis_body,
        tip_distance: projectile.params.length - axis_offset(projectile),
        initial_axis: Vector::x(),
        start_time: world.time(),
    };
    let outputs = open_outputs(options, world, gauge)?;
    // The run is a `Simulation` (the state every output reads) for its duration; the world goes back
    // to the caller whatever the outcome (a run split over MPI ranks that fails gives back the world it
    // started from).
    let placeholder = World::new(world.gravity(), world.materials().clone(), 0.0);
    let world_in = std::mem::replace(world, placeholder);
    let mut sim = penetration_simulation(config, world_in, projectile, index, time_step, options);
    let run = step_impact(config, &mut sim, projectile, options, outputs, progress);
    *world = sim.world;
    let (run, ranks) = run?;
    let mut report = report(
        config,
        world,
        (projectile, index),
        &start_positions,
        kinetic0,
        dt,
        run,
        start.elapsed(),
    );
    report.ranks = ranks;
    Ok(report)
}

/// What a run split over MPI ranks cannot do, refused before any work.
fn check_distributed(
    config: &ExperimentConfig,
    options: &PenetrationOptions,
) -> Result<(), PenetrationError> {
    if !options.distributed {
        return Ok(());
    }
    if cfg!(not(feature = "mpi")) {
        return Err(PenetrationError::NoMpi);
    }
    if config.sleeping.penetration {
        return Err(PenetrationError::DistributedSleeping);
    }
    Ok(())
}

/// Whether this process writes the run's files: every process of a run in one, rank 0 of a run split
/// over MPI ranks.
pub fn writes_files(options: &PenetrationOptions) -> bool {
    #[cfg(feature = "mpi")]
    if options.distributed {
        return super::distributed::rank() == 0;
    }
    let _ = options;
    true
}

/// Runs the impact in this process or split over the MPI ranks ([`PenetrationOptions::distributed`]);
/// `sim` ends at the run's last state.
fn step_impact(
    config: &ExperimentConfig,
    sim: &mut Simulation,
    projectile: &Projectile,
    options: &PenetrationOptions,
    outputs: RunOutputs,
    progress: impl FnMut(&MonitorRow),
) -> Result<(ImpactRun, Option<RankFacts>), PenetrationError> {
    let start_step = sim.world.step_index();
    if !options.distributed {
        let mut stepper = LocalStepper::new(sim);
        let run = run_impact(
            config,
            &mut stepper,
            start_step,
            projectile,
            options,
            outputs,
            progress,
        )?;
        return Ok((run, None));
    }
    #[cfg(feature = "mpi")]
    {
        let mut stepper = super::distributed::DistributedStepper::new(sim)?;
        let run = run_impact(
            config,
            &mut stepper,
            start_step,
            projectile,
            options,
            outputs,
            progress,
        )?;
        let facts = stepper.facts();
        *sim = stepper.into_whole()?;
        Ok((run, Some(facts)))
    }
    #[cfg(not(feature = "mpi"))]
    Err(PenetrationError::NoMpi)
}

/// The outputs of a run: the monitor series, driven step by step through the [`Output`] trait (the run
/// reads its rows), and the other outputs of [`PenetrationFiles`] in an [`OutputSet`] (empty on the
/// ranks other than 0 of a run split over MPI ranks).
struct RunOutputs {
    monitors: MonitorSeries,
    others: OutputSet<'static>,
    /// The VTK frames' schedule, known on every rank: the whole state is gathered at those steps, a
    /// collective every rank must enter, though only rank 0 writes.
    frames: Option<Schedule>,
}

impl RunOutputs {
    /// Whether the outputs read the whole state after step `step` (the same answer on every rank).
    fn wants_state(&self, step: u64) -> bool {
        self.frames.is_some_and(|s| s.due(step)) || self.others.wants_state(step)
    }
}

fn open_outputs(
    options: &PenetrationOptions,
    world: &World,
    gauge: ProjectileGauge,
) -> Result<RunOutputs, PenetrationError> {
    let start_step = world.step_index();
    let frames = options
        .files
        .as_ref()
        .and_then(|f| f.vtk_every)
        .map(|every| Schedule {
            start_step,
            last_step: u64::MAX,
            every: Some(every),
            at_start: true,
            at_end: false,
        });
    let files = options.files.as_ref().filter(|_| writes_files(options));
    let monitors = MonitorSeries::new(gauge, start_step, files.map(|f| f.dir.join(&f.monitors)));
    let mut others = OutputSet::new();
    if let Some(f) = files {
        std::fs::create_dir_all(&f.dir).map_err(|e| in_dir(&f.dir, e))?;
        if let Some(schedule) = frames {
            let writer =
                VtkWriter::new(&f.dir, world, f.vtk_encoding).map_err(|e| in_dir(&f.dir, e))?;
            others.push(VtkFrames::new(writer, schedule));
        }
    }
    Ok(RunOutputs {
        monitors,
        others,
        frames,
    })
}

fn in_dir(dir: &std::path::Path, e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("{}: {e}", dir.display()))
}

/// The penetration run as a [`Simulation`]: the projectile tracked, its input frame that of the
/// projectile's shape file, the rocks' the principal frames they are stored in.
fn penetration_simulation(
    config: &ExperimentConfig,
    world: World,
    projectile: &Projectile,
    index: usize,
    time_step: TimeStepInfo,
    options: &PenetrationOptions,
) -> Simulation {
    let imp = &config.impact;
    let dt = time_step.dt;
    let mut params = StepParams::new(dt);
    params.damping = ViscousDamping::None;
    params.sleeping = config.sleeping.params(config.sleeping.penetration);
    let run_steps = options
        .max_steps
        .unwrap_or_else(|| (imp.max_time / dt).ceil() as u64);
    let mut frames = vec![Pose::identity(); world.body_count()];
    frames[index] = projectile.input_from_body;
    Simulation {
        end_time: world.time() + imp.max_time,
        steps: world.step_index() + run_steps,
        world,
        params,
        time_step,
        output_every: 1,
        tracked: vec![index],
        frames,
    }
}

/// What the stepping loop of a run gathered.
struct ImpactRun {
    outcome: Outcome,
    rows: Vec<MonitorRow>,
    steps: u64,
    counters: StepCounters,
    max_overlap: Real,
    warned: u64,
    snapshots: Vec<Snapshot>,
}

/// Steps the world until the projectile exits, stops, or a limit is reached, handing each step to the
/// outputs. The run starts at step `start_step`.
fn run_impact<S: ImpactStepper>(
    config: &ExperimentConfig,
    stepper: &mut S,
    start_step: u64,
    projectile: &Projectile,
    options: &PenetrationOptions,
    mut outputs: RunOutputs,
    mut progress: impl FnMut(&MonitorRow),
) -> Result<ImpactRun, PenetrationError> {
    let mut counters = StepCounters::default();
    let (mut steps, mut max_overlap) = (0u64, 0.0 as Real);
    let mut warned_steps = Vec::new();
    let mut snapshots = Vec::new();
    let mut pending: Vec<Real> = options.snapshot_tip_x.clone();
    pending.sort_by(|a, b| b.total_cmp(a));
    let gauge = *outputs.monitors.gauge();
    if outputs.wants_state(start_step) {
        outputs.others.observe(stepper.whole()?, start_step)?;
    }
    let outcome = loop {
        if options.stop.is_some() && stepper.agree(stop::requested(options.stop.as_ref())) {
            return Err(PenetrationError::Interrupted { steps });
        }
        let facts = stepper.step()?;
        counters.merge(&facts.counters);
        steps += 1;
        max_overlap = max_overlap.max(facts.max_overlap_ratio);
        warned_steps.push(facts.warned);
        let at = start_step + steps;
        let (row, body) = stepper.projectile(&gauge)?;
        outputs.monitors.push(row);
        if outputs.wants_state(at) {
            outputs.others.observe(stepper.whole()?, at)?;
        }
        while pending.last().is_some_and(|&x| row.tip.x >= x) {
            pending.pop();
            snapshots.push(snapshot(&stepper.whole()?.world, row.time, row.tip));
        }
        if steps.is_multiple_of(100) {
            progress(&row);
        }
        if let Some(outcome) = end_of_run(config, &body, projectile, &row, steps, options) {
            break outcome;
        }
    };
    outputs.monitors.flush()?;
    outputs.others.finish()?;
    let rows = outputs.monitors.into_rows();
    let (max_overlap, warned) = stepper.overlaps(max_overlap, &warned_steps);
    if !options.snapshot_tip_x.is_empty() {
        let last = rows.last().expect("at least one step");
        snapshots.push(snapshot(&stepper.whole()?.world, last.time, last.tip));
    }
    Ok(ImpactRun {
        outcome,
        rows,
        steps,
        counters,
        max_overlap,
        warned,
        snapshots,
    })
}

/// How the run ends after the step of `row`, if it does.
fn end_of_run(
    config: &ExperimentConfig,
    body: &RigidBody,
    projectile: &Projectile,
    row: &MonitorRow,
    steps: u64,
    options: &PenetrationOptions,
) -> Option<Outcome> {
    let imp = &config.impact;
    let axis = body.orientation * projectile.axis_body;
    let base_x = (row.tip - axis * projectile.params.length).x;
    if base_x > config.layer.length {
        Some(Outcome::Exited)
    } else if body.velocity.norm() < 0.01 * imp.speed {
        Some(Outcome::Stopped)
    } else if row.time >= imp.max_time {
        Some(Outcome::TimeLimit)
    } else if options.max_steps.is_some_and(|max| steps >= max) {
        Some(Outcome::StepLimit)
    } else {
        None
    }
}

/// The report of a run from what its loop gathered and the world at its end.
#[allow(clippy::too_many_arguments)]
fn report(
    config: &ExperimentConfig,
    world: &World,
    (projectile, index): (&Projectile, usize),
    start_positions: &[Point],
    kinetic0: Real,
    dt: Real,
    run: ImpactRun,
    wall_time: Duration,
) -> PenetrationReport {
    let ImpactRun {
        outcome,
        rows,
        steps,
        counters,
        max_overlap,
        warned,
        snapshots,
    } = run;
    let imp = &config.impact;
    let last = *rows.last().expect("at least one step");
    let body = world.body(index);
    let aim_z = rows.first().map_or(0.0, |r| r.position.z);
    let zone = |fraction| disturbed_zone(config, world, index, start_positions, aim_z, fraction);
    let (disturbed_rocks, width) = zone(imp.disturbed_threshold);
    let disturbed_by_threshold = DISTURBED_THRESHOLDS
        .iter()
        .map(|&f| {
            let (n, w) = zone(f);
            (f, n, w / config.rock.mean_size)
        })
        .collect();
    let energy = world.energy();
    let kinetic = body.translational_kinetic_energy() + body.rotational_kinetic_energy();
    let max_of = |of: fn(&MonitorRow) -> Real| rows.iter().map(of).fold(0.0, Real::max);
    PenetrationReport {
        outcome,
        dt,
        steps,
        rocks: world.bodies().len() - 1,
        projectile_mass: body.mass,
        residual_speed: body.velocity.norm(),
        residual_axial_velocity: body.velocity.dot(&Vector::x()),
        exit_time: (outcome == Outcome::Exited).then_some(last.time),
        final_velocity_deflection: last.velocity_deflection,
        final_axis_deflection: last.axis_deflection,
        max_velocity_deflection: max_of(|r| r.velocity_deflection),
        max_axis_deflection: max_of(|r| r.axis_deflection),
        max_axial_force: max_of(|r| r.axial_force.abs()),
        disturbed_rocks,
        disturbed_by_threshold,
        disturbed_width: width,
        disturbed_width_sizes: width / config.rock.mean_size,
        ledger_balance_relative: energy.balance / kinetic0,
        projectile_energy_loss: kinetic0 - kinetic,
        dissipated_damping: energy.dissipated_damping,
        dissipated_friction: energy.dissipated_friction,
        max_overlap_ratio: max_overlap,
        steps_with_overlap_warnings: warned,
        resistance: ResistanceStatistics::from_rows(
            &rows,
            config.layer.length,
            projectile.params.length,
            ((config.rock.mean_size / imp.speed) / dt).round() as usize,
        ),
        start_positions: start_positions.to_vec(),
        snapshots,
        wall_time,
        asleep_fraction: counters.sleeping_body_steps as Real
            / (steps as Real * (world.bodies().len() - 1) as Real),
        counters,
        rows,
        ranks: None,
    }
}

/// The rocks displaced by more than `fraction` of the mean size since `start_positions`, and the width of
/// the zone they started in (m; see the module docs).
fn disturbed_zone(
    config: &ExperimentConfig,
    world: &World,
    index: usize,
    start_positions: &[Point],
    aim_z: Real,
    fraction: Real,
) -> (usize, Real) {
    let aim_y = 0.5 * config.layer.width;
    let threshold = fraction * config.rock.mean_size;
    let mut radii: Vec<Real> = (0..world.bodies().len())
        .filter(|&i| i != index && world.bodies()[i].is_dynamic())
        .filter(|&i| (world.bodies()[i].position - start_positions[i]).norm() > threshold)
        .map(|i| {
            let p = start_positions[i];
            ((p.y - aim_y).powi(2) + (p.z - aim_z).powi(2)).sqrt()
        })
        .collect();
    radii.sort_by(|a, b| a.total_cmp(b));
    let width = if radii.is_empty() {
        0.0
    } else {
        let k = ((0.95 * radii.len() as Real).ceil() as usize).clamp(1, radii.len()) - 1;
        2.0 * radii[k]
    };
    (radii.len(), width)
}

fn snapshot(world: &World, time: Real, tip: Point) -> Snapshot {
    Snapshot {
        time,
        tip,
        poses: (0..world.bodies().len()).map(|i| world.pose(i)).collect(),
    }
}

/// Distance from the base to the centre of mass along the axis (m): the centre of mass lies at
/// x = `input_from_body.translation.x` of the projectile's input frame, whose base is at x = 0.
fn axis_offset(projectile: &Projectile) -> Real {
    projectile.input_from_body.translation.vector.x
}

/// The penetration's steps at `dt` (at most `impact.max_time` / Δt), refused above the limit.
/// `dt_bound` says whether `dt` is the run's Δt or only the upper bound known before generation.
pub fn check_penetration_steps(
    config: &ExperimentConfig,
    dt: Real,
    dt_bound: bool,
) -> Result<(), LimitError> {
    let imp = &config.impact;
    let steps = imp.max_time / dt;
    let rows_gb = steps * std::mem::size_of::<MonitorRow>() as Real / 1e9;
    let rule = if dt_bound {
        "known before generation: Δt ≤"
    } else {
        "Δt = min(the rocks' Δt,"
    };
    let reason = format!(
        "impact.max_time = {:?} s over Δt, {rule} impact.travel_per_step {:?} × rock.mean_size {:?} m / impact.speed {:?} m/s{}; one monitor row per step, {rows_gb:.3e} GB",
        imp.max_time,
        imp.travel_per_step,
        config.rock.mean_size,
        imp.speed,
        if dt_bound { "" } else { ")" }
    );
    within(config, "penetration", steps, dt, reason)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run split over MPI ranks is refused before any work: without MPI in the build, and (with it)
    /// when it would need what the ranks do not carry.
    #[test]
    fn a_distributed_run_is_refused_where_it_cannot_give_one_process_bits() {
        let config = ExperimentConfig::quick();
        let distributed = PenetrationOptions {
            distributed: true,
            ..Default::default()
        };
        let one_process = PenetrationOptions::default();
        assert!(check_distributed(&config, &one_process).is_ok());
        let refused = check_distributed(&config, &distributed);
        if cfg!(not(feature = "mpi")) {
            assert!(
                matches!(refused, Err(PenetrationError::NoMpi)),
                "without the mpi feature: {refused:?}, expected NoMpi"
            );
            return;
        }
        assert!(refused.is_ok(), "quick.toml split over ranks: {refused:?}");
        let mut sleeping = config;
        sleeping.sleeping.penetration = true;
        let refused = check_distributed(&sleeping, &distributed);
        assert!(
            matches!(refused, Err(PenetrationError::DistributedSleeping)),
            "sleeping.penetration = true: {refused:?}, expected DistributedSleeping"
        );
    }
}
