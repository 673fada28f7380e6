//! The packing run: deposition, compaction, hold and (with density scaling) restore, as
//! [`crate::packing`]'s module docs describe them, driven one stage after the other by a [`Packer`] that
//! holds what every stage shares (the step parameters, the scratch space, the report being filled).

use std::time::Instant;

use super::config::{DepositionDamping, ExperimentConfig};
use super::limits::check_packing_steps;
use super::packing::{
    apply_local_damping, bed_overlap, bed_top, max_speed, packing_time_step, set_rock_density,
    top_wall_height, PackingError, PackingReport, PackingSample, STALL_FRACTION, TOP_WALL,
    TRACE_EVERY,
};
use super::stop::{self, StopCheck};
use polydem::dynamics::ViscousDamping;
use polydem::math::{Real, Vector};
use polydem::shape::Shape;
use polydem::world::{step, StepParams, StepScratch, World};

/// Standard gravity (m/s²) of the experiment's world.
const G: Real = 9.81;

/// Stage indices, as in [`super::packing::STAGE_NAMES`] and the report's counters.
const DEPOSITION: usize = 0;
const COMPACTION: usize = 1;
const HOLD: usize = 2;
const RESTORE: usize = 3;

/// Deposition, compaction and hold (see [`crate::packing`]'s module docs). `progress` is called every few
/// hundred steps with (stage, simulated time, bed top).
pub fn pack(
    config: &ExperimentConfig,
    world: &mut World,
    progress: impl FnMut(&str, Real, Real),
) -> Result<PackingReport, PackingError> {
    pack_with_stop(config, world, None, progress)
}

/// [`pack`] that asks `stop` before each step whether to end there ([`PackingError::Interrupted`]).
pub fn pack_with_stop(
    config: &ExperimentConfig,
    world: &mut World,
    stop: Option<&StopCheck>,
    progress: impl FnMut(&str, Real, Real),
) -> Result<PackingReport, PackingError> {
    let start = Instant::now();
    let mut packer = Packer::new(config, world, stop, progress)?;
    let initial_top = top_wall_height(world);
    let potential0: Real = world
        .bodies()
        .iter()
        .map(|b| b.mass * G * b.position.z)
        .sum();
    packer.deposit(world, initial_top)?;
    packer.report.ledger_balance_relative[0] = world.energy().balance / potential0;
    packer.report.deposited_top = bed_top(world);
    packer.compact(world, initial_top)?;
    packer.report.ledger_balance_relative[1] = world.energy().balance / potential0;
    packer.hold(world)?;
    packer.report.bed_overlap_after_hold = bed_overlap(world, config.rock.mean_size);
    if config.packing.packing_density_scale.is_some() {
        packer.restore(world)?;
    }
    let mut report = packer.report;
    finish(config, world, &mut report);
    report.ledger_balance_relative[2] = world.energy().balance / potential0;
    report.wall_time = start.elapsed();
    Ok(report)
}

/// What the stages share.
struct Packer<'a, P> {
    config: &'a ExperimentConfig,
    stop: Option<&'a StopCheck>,
    progress: P,
    params: StepParams,
    scratch: StepScratch,
    /// Cundall's local damping coefficient, when the deposition takes it instead of the viscous one.
    local_alpha: Option<Real>,
    report: PackingReport,
}

impl<'a, P: FnMut(&str, Real, Real)> Packer<'a, P> {
    /// Scales the density when asked (before the first step: the ledger has no initial energy yet,
    /// nothing to book), takes the packing's Δt, sets the damping and the drop speed.
    fn new(
        config: &'a ExperimentConfig,
        world: &mut World,
        stop: Option<&'a StopCheck>,
        progress: P,
    ) -> Result<Self, PackingError> {
        let p = &config.packing;
        let scale = p.packing_density_scale.unwrap_or(1.0);
        if p.packing_density_scale.is_some() {
            set_rock_density(world, config.rock.density * scale)?;
        }
        let (dt, contact_time) = packing_time_step(config, world)?;
        check_packing_steps(config, dt)?;
        let mut params = StepParams::new(dt);
        let local_alpha = match p.deposition_damping {
            Some(DepositionDamping::Local) => p.local_damping,
            _ => None,
        };
        params.damping = match local_alpha {
            Some(_) => ViscousDamping::None,
            None => ViscousDamping::MassProportional(p.viscous_rate),
        };
        if let Some(v0) = p.drop_speed {
            for i in 0..world.body_count() {
                if world.body(i).is_dynamic() {
                    world.set_body_velocity(i, Vector::new(0.0, 0.0, -v0))?;
                }
            }
        }
        params.sleeping = config.sleeping.params(config.sleeping.packing);
        let report = PackingReport {
            rocks: world.bodies().len(),
            dt,
            contact_time,
            density_scale: scale,
            ..Default::default()
        };
        Ok(Self {
            config,
            stop,
            progress,
            params,
            scratch: StepScratch::default(),
            local_alpha,
            report,
        })
    }

    /// One step of `stage` at `dt`, unless the stop check asks to end here.
    fn step(&mut self, world: &mut World, stage: usize, dt: Real) -> Result<(), PackingError> {
        if stop::requested(self.stop) {
            return Err(PackingError::Interrupted { time: world.time() });
        }
        self.params.dt = dt;
        let r = step(&self.params, world, &mut self.scratch)?;
        if let Some(alpha) = self.local_alpha {
            let removed = apply_local_damping(world, alpha, dt);
            world.record_viscous_dissipation(removed);
        }
        self.report.max_overlap_ratio = self.report.max_overlap_ratio.max(r.max_overlap_ratio);
        self.report.counters[stage].merge(&r.counters);
        Ok(())
    }

    /// The bed now, as a trace row of `stage` after its `step`-th step.
    fn sample(&self, world: &World, stage: usize, step: u64) -> PackingSample {
        let e = world.energy();
        let kinetic = e.translational_kinetic + e.rotational_kinetic;
        PackingSample {
            stage,
            step,
            time: world.time(),
            max_speed: max_speed(world),
            kinetic_energy: kinetic,
            kinetic_fraction: kinetic / lift_energy(world, self.config.rock.mean_size),
            bed_top: bed_top(world),
            top_wall: top_wall_height(world),
            wall_force: top_wall_force(world),
        }
    }

    /// Appends a trace row of `stage` and reports `height` to the progress callback.
    fn trace(&mut self, world: &World, stage: usize, step: u64, height: Real) {
        let row = self.sample(world, stage, step);
        self.report.trace.push(row);
        (self.progress)(super::packing::STAGE_NAMES[stage], world.time(), height);
    }

    /// Stage 1: falls until calm after the minimum time, or until the longest deposition time.
    fn deposit(&mut self, world: &mut World, initial_top: Real) -> Result<(), PackingError> {
        let p = &self.config.packing;
        let min_time = deposition_min_time(self.config, world, initial_top);
        loop {
            self.step(world, DEPOSITION, self.report.dt)?;
            self.report.deposition_steps += 1;
            let t = world.time();
            if self.report.deposition_steps.is_multiple_of(TRACE_EVERY) {
                let row = self.sample(world, DEPOSITION, self.report.deposition_steps);
                self.report.trace.push(row);
                (self.progress)("deposition", t, row.bed_top);
                let calm = row.max_speed < p.settle_speed
                    && p.settle_kinetic_fraction
                        .is_none_or(|f| row.kinetic_fraction < f);
                if (t >= min_time && calm) || t >= p.max_deposition_time {
                    break;
                }
            }
        }
        self.report.deposition_time = world.time();
        Ok(())
    }

    /// Stage 2: when the bed stands above the layer height, the top wall is placed on it and driven down
    /// by the force-capped servo until it reaches the height or stalls for the hold time.
    fn compact(&mut self, world: &mut World, initial_top: Real) -> Result<(), PackingError> {
        let (config, t0) = (self.config, world.time());
        let target = config.layer.height;
        if self.report.deposited_top > target {
            // Place the wall on the bed (a translation along its normal, before it touches anything).
            let lift = self.report.deposited_top - initial_top;
            let mut translation = world.walls()[TOP_WALL].pose.translation.vector;
            translation.z += lift;
            world.set_wall_translation(TOP_WALL, translation)?;
            // The cap scales with the weights (density scaling, see the module docs).
            let p = &config.packing;
            let force_cap = self.report.density_scale
                * p.compaction_pressure
                * config.layer.length
                * config.layer.width;
            let mut stalled_since: Option<Real> = None;
            while top_wall_height(world) > target {
                // Servo: full speed on a loose bed, slowing to a stop as the wall force nears the cap.
                let fraction = (1.0 - top_wall_force(world) / force_cap).clamp(0.0, 1.0);
                let velocity = Vector::new(0.0, 0.0, -p.compaction_speed * fraction);
                world.set_wall_velocity(TOP_WALL, velocity)?;
                self.step(world, COMPACTION, self.report.dt)?;
                self.report.compaction_steps += 1;
                if self.report.compaction_steps.is_multiple_of(TRACE_EVERY) {
                    let steps = self.report.compaction_steps;
                    self.trace(world, COMPACTION, steps, top_wall_height(world));
                }
                if fraction < STALL_FRACTION {
                    let since = *stalled_since.get_or_insert(world.time());
                    if world.time() - since > p.hold_time {
                        self.report.compaction_stalled = true;
                        break;
                    }
                } else {
                    stalled_since = None;
                }
            }
            world.set_wall_velocity(TOP_WALL, Vector::zeros())?;
        }
        self.report.compaction_time = world.time() - t0;
        Ok(())
    }

    /// Stage 3: the top wall stopped, the bed relaxes for the hold time.
    fn hold(&mut self, world: &mut World) -> Result<(), PackingError> {
        let hold_end = world.time() + self.config.packing.hold_time;
        while world.time() < hold_end {
            self.step(world, HOLD, self.report.dt)?;
            self.report.hold_steps += 1;
            if self.report.hold_steps.is_multiple_of(TRACE_EVERY) {
                let steps = self.report.hold_steps;
                self.trace(world, HOLD, steps, bed_top(world));
            }
        }
        Ok(())
    }

    /// Stage 4 (density scaling only): a geometric ramp of the density from s ρ to ρ over the first half
    /// of `restore_time`, then the true density for the second half, the top wall backing off while it
    /// pushes harder than its force at the current weights.
    fn restore(&mut self, world: &mut World) -> Result<(), PackingError> {
        let (config, scale) = (self.config, self.report.density_scale);
        let p = &config.packing;
        let force0 = top_wall_force(world);
        let restore_time = p.restore_time.unwrap_or(0.0);
        let (t0, top0) = (world.time(), top_wall_height(world));
        let mut sigma = scale;
        loop {
            let tau = ((world.time() - t0) / (0.5 * restore_time)).min(1.0);
            let next = if tau >= 1.0 {
                1.0
            } else {
                scale.powf(1.0 - tau)
            };
            if next != sigma {
                restore_density_to(config, world, next)?;
                sigma = next;
            }
            if world.time() >= t0 + restore_time {
                break;
            }
            let (dt_now, _) = packing_time_step(config, world)?;
            // Servo: back off at up to the compaction speed while the wall pushes harder than F σ/s.
            let target = force0 * sigma / scale;
            let excess = if target > 0.0 {
                (top_wall_force(world) / target - 1.0).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let velocity = Vector::new(0.0, 0.0, p.compaction_speed * excess);
            world.set_wall_velocity(TOP_WALL, velocity)?;
            self.step(world, RESTORE, dt_now)?;
            self.report.restore_steps += 1;
            if self.report.restore_steps.is_multiple_of(TRACE_EVERY) {
                let steps = self.report.restore_steps;
                self.trace(world, RESTORE, steps, top_wall_height(world));
            }
        }
        world.set_wall_velocity(TOP_WALL, Vector::zeros())?;
        self.report.restore_dt = packing_time_step(config, world)?.0;
        self.report.restore_wall_rise = top_wall_height(world) - top0;
        self.report.restore_wall_force = [force0, top_wall_force(world)];
        Ok(())
    }
}

/// Sets the rocks' density to `fraction` ρ: exactly ρ at `fraction` = 1 (the bits of an unscaled bed).
/// The change of mechanical energy is booked as external work once the ledger has its initial total.
fn restore_density_to(
    config: &ExperimentConfig,
    world: &mut World,
    fraction: Real,
) -> Result<(), PackingError> {
    let density = if fraction == 1.0 {
        config.rock.density
    } else {
        config.rock.density * fraction
    };
    let changed = set_rock_density(world, density)?;
    if world.ledger().initial_total().is_some() {
        world.record_external_work(changed);
    }
    Ok(())
}

/// The end of the run: the bed's overlaps, top, solid fraction and largest speed.
fn finish(config: &ExperimentConfig, world: &World, report: &mut PackingReport) {
    report.bed_overlap_final = bed_overlap(world, config.rock.mean_size);
    report.final_top = bed_top(world);
    report.top_wall = top_wall_height(world);
    let volume: Real = (0..world.bodies().len())
        .map(|i| match world.shape(i) {
            Shape::Polyhedron(s) => s.mass_properties().volume,
            _ => 0.0,
        })
        .sum();
    report.solid_fraction = volume / (config.layer.length * config.layer.width * report.final_top);
    report.final_max_speed = max_speed(world);
}

/// The shortest deposition: for a pre-collapsed bed the free fall over the gaps stacked under the top
/// rock, otherwise the fall of the generation height from the drop speed v0, (√(v0² + 2 g h) − v0) / g.
fn deposition_min_time(config: &ExperimentConfig, world: &World, initial_top: Real) -> Real {
    let p = &config.packing;
    match p.collapse_gap {
        Some(gap) => (2.0 * (bed_top(world) / config.rock.mean_size) * gap * config.rock.mean_size
            / G)
            .sqrt(),
        None => {
            let v0 = p.drop_speed.unwrap_or(0.0);
            ((v0 * v0 + 2.0 * G * initial_top).sqrt() - v0) / G
        }
    }
}

/// Energy scale of the settle criterion: Σ m g d̄ over the dynamic rocks (at the masses of the moment:
/// scaled or true).
fn lift_energy(world: &World, mean_size: Real) -> Real {
    world
        .bodies()
        .iter()
        .filter(|b| b.is_dynamic())
        .map(|b| b.mass * G * mean_size)
        .sum()
}

/// The top wall's vertical contact force (N).
fn top_wall_force(world: &World) -> Real {
    world
        .loads()
        .wall_forces()
        .get(TOP_WALL)
        .map_or(0.0, |f| f.z)
}
