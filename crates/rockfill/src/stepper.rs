//! Who takes the impact's steps: the engine's `step` on the whole world in this process
//! ([`LocalStepper`]), or a run split over the ranks of an MPI job (`distributed`, feature `mpi`). The
//! penetration's loop asks only for what both give bit for bit: a step, the projectile's monitor row and
//! body after it, and the whole state when a snapshot or an output needs it.

use super::monitors::{MonitorRow, ProjectileGauge};
use super::penetration_error::PenetrationError;
use polydem::dynamics::RigidBody;
use polydem::math::Real;
use polydem::scene::Simulation;
use polydem::world::{step, StepCounters, StepScratch};

/// What the run keeps of one step's report.
#[derive(Clone, Debug, Default)]
pub(crate) struct StepFacts {
    /// The step's stage timers and counters.
    pub counters: StepCounters,
    /// The largest overlap / particle size at the end of the step (of the pairs this process evaluated).
    pub max_overlap_ratio: Real,
    /// Whether some contact (that this process evaluated) was deeper than the warning fraction.
    pub warned: bool,
}

/// Steps the penetration's world.
pub(crate) trait ImpactStepper {
    /// One step of the whole world.
    fn step(&mut self) -> Result<StepFacts, PenetrationError>;
    /// The monitor row of the current state (measured with `gauge`) and the projectile's body.
    fn projectile(
        &mut self,
        gauge: &ProjectileGauge,
    ) -> Result<(MonitorRow, RigidBody), PenetrationError>;
    /// The whole run at the current state (outputs, snapshots).
    fn whole(&mut self) -> Result<&Simulation, PenetrationError>;
    /// Whether to stop, given whether this process was asked to: every process of the run takes the
    /// same decision.
    fn agree(&mut self, requested: bool) -> bool;
    /// The largest overlap ratio of the run and the number of steps with an overlap warning, from this
    /// process's largest ratio and its flag of each step ([`StepFacts`]).
    fn overlaps(&mut self, max_overlap_ratio: Real, warned: &[bool]) -> (Real, u64);
}

/// One rank's facts of a run split over MPI ranks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RankFacts {
    /// This rank and the number of ranks.
    pub rank: usize,
    pub ranks: usize,
    /// Times the subdomains were cut (the first included; one per broad-phase rebuild after it).
    pub cuts: u64,
    /// Of those, the cuts that bisected the whole world again (the others migrated bodies between
    /// neighbours).
    pub bisections: u64,
    /// Bodies this rank owned and held as ghosts, averaged over the steps.
    pub mean_owned: Real,
    pub mean_ghosts: Real,
    /// Bytes this rank sent: ghost states after each step, rebuild agreements, bodies and contact entries at
    /// the cuts, and the gathers of the run itself (the projectile's row each step, snapshots, the end
    /// state).
    pub ghost_bytes: u64,
    pub agreement_bytes: u64,
    pub cut_bytes: u64,
    pub gather_bytes: u64,
    /// Times the rank owning the projectile changed from one monitored step to the next (the same on
    /// every rank).
    pub projectile_owner_changes: u64,
}

/// The whole world stepped in this process.
pub(crate) struct LocalStepper<'a> {
    sim: &'a mut Simulation,
    scratch: StepScratch,
}

impl<'a> LocalStepper<'a> {
    pub fn new(sim: &'a mut Simulation) -> Self {
        Self {
            sim,
            scratch: StepScratch::default(),
        }
    }
}

impl ImpactStepper for LocalStepper<'_> {
    fn step(&mut self) -> Result<StepFacts, PenetrationError> {
        let report = step(&self.sim.params, &mut self.sim.world, &mut self.scratch)?;
        Ok(StepFacts {
            warned: !report.overlap_warnings.is_empty(),
            max_overlap_ratio: report.max_overlap_ratio,
            counters: report.counters,
        })
    }

    fn projectile(
        &mut self,
        gauge: &ProjectileGauge,
    ) -> Result<(MonitorRow, RigidBody), PenetrationError> {
        let world = &self.sim.world;
        Ok((gauge.row(world), *world.body(gauge.index)))
    }

    fn whole(&mut self) -> Result<&Simulation, PenetrationError> {
        Ok(self.sim)
    }

    fn agree(&mut self, requested: bool) -> bool {
        requested
    }

    fn overlaps(&mut self, max_overlap_ratio: Real, warned: &[bool]) -> (Real, u64) {
        let steps = warned.iter().filter(|&&w| w).count() as u64;
        (max_overlap_ratio, steps)
    }
}
