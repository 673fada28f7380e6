//! The impact split over the ranks of an MPI job (feature `mpi`): [`polydem_mpi::DistributedRun`] steps
//! the world, each rank the bodies of its subdomain and their ghosts, with the bits of one process.
//!
//! # What every rank sees
//! The monitor row is a function of the projectile alone (its state, its contact force, the rocks pressing
//! on it), so the rank that owns the projectile computes it on its part, whose contact store holds every
//! pair of the projectile as one process's does, and hands it with the projectile's body to every rank:
//! every row, the snapshots' timing and the end of the run are one process's bit for bit. The whole world
//! (snapshots, the state at the end) is gathered from the owners of its bodies and contacts.
//!
//! # The world it starts from
//! A bed read from its checkpoint has its loads evaluated, which [`DistributedRun::new`] refuses; removing
//! the left and right walls and adding the projectile (`add_projectile`) marks them stale, so the world the
//! penetration starts from is fresh. One process's first step then evaluates the loads and rebuilds its
//! broad phase (the body count changed), as every part's first step does (its broad phase is empty), and
//! the packed contacts' tangential springs go to the parts with the world.
//!
//! # A projectile at 1200 m/s
//! The subdomains are cut again at every broad-phase rebuild, which the projectile forces every few steps
//! (it travels `impact.travel_per_step` = 2 % of a mean rock size per step in the experiment files, or
//! less; the skin is 5 %). Between two cuts a body moves at most the skin plus one step's travel (the
//! rebuild rule lets the two largest moves add up to the skin), so the ghost layer's allowance of 1.5
//! skins holds while no body travels more than half the skin in a step: up to 1500 m/s with these
//! values. A faster body stops the run with `HaloExceeded` at the next cut. The parts run
//! without the time-step check (it reads the state only, so one process's bits do not depend on it).
//!
//! # Limits
//! - Sleeping is refused (the parts do not carry the sleep state).
//! - VTK frames gather the whole world on every rank at each frame (every rank knows the schedule; rank 0
//!   writes the frame as one process does, the same bytes): O(N) traffic per frame.
//! - The energy ledger's terms are the whole world's, added over the ranks' shares: one process's up to
//!   rounding, not bit for bit.
//! - The step counters are those of this rank's part (they include its ghosts' pairs); the largest overlap
//!   and the steps with overlap warnings are reduced over the ranks (a pair is evaluated, at one
//!   process's state, on every rank that holds it).
//! - A step that fails on one rank leaves the others waiting in the next collective: the caller aborts the
//!   job (`MPI_Abort`) on an error.

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use polydem::dynamics::RigidBody;
use polydem::math::Real;
use polydem::scene::Simulation;
use polydem_mpi::{mpi, DistributedRun};

use super::monitors::{MonitorRow, ProjectileGauge};
use super::penetration_error::PenetrationError;
use super::stepper::{ImpactStepper, RankFacts, StepFacts};

/// This process's rank in `MPI_COMM_WORLD` (MPI initialised by the caller).
pub fn rank() -> usize {
    SimpleCommunicator::world().rank() as usize
}

/// The run split over the ranks, and the whole run as of the last gather.
pub(crate) struct DistributedStepper {
    run: DistributedRun,
    whole: Simulation,
    /// Σ over the steps of the bodies owned and held as ghosts after each, and the steps.
    held: (usize, usize, usize),
    /// The rank that owned the projectile at its last row, and how often that rank changed.
    projectile_owner: Option<usize>,
    projectile_owner_changes: u64,
}

impl DistributedStepper {
    /// Splits `sim`'s world (every rank passes the same one) over the ranks.
    pub fn new(sim: &Simulation) -> Result<Self, PenetrationError> {
        if sim.params.sleeping.enabled {
            return Err(PenetrationError::DistributedSleeping);
        }
        let run = DistributedRun::new(sim.world.clone(), sim.params)?;
        Ok(Self {
            run,
            whole: sim.clone(),
            held: (0, 0, 0),
            projectile_owner: None,
            projectile_owner_changes: 0,
        })
    }

    /// This rank's facts so far.
    pub fn facts(&self) -> RankFacts {
        let traffic = self.run.traffic();
        let (owned, ghosts, steps) = self.held;
        let mean = |n: usize| n as Real / steps.max(1) as Real;
        RankFacts {
            rank: self.run.rank(),
            ranks: SimpleCommunicator::world().size() as usize,
            cuts: self.run.cuts,
            bisections: self.run.bisections,
            mean_owned: mean(owned),
            mean_ghosts: mean(ghosts),
            ghost_bytes: traffic.ghosts.bytes,
            agreement_bytes: traffic.agreements.bytes,
            cut_bytes: traffic.cuts.bytes,
            gather_bytes: traffic.gathers.bytes,
            projectile_owner_changes: self.projectile_owner_changes,
        }
    }

    /// The whole run at the current state.
    pub fn into_whole(mut self) -> Result<Simulation, PenetrationError> {
        self.whole.world = self.run.gather_world()?;
        Ok(self.whole)
    }
}

impl ImpactStepper for DistributedStepper {
    fn step(&mut self) -> Result<StepFacts, PenetrationError> {
        let report = self.run.step()?;
        let (owned, ghosts) = self.run.part_size();
        self.held = (self.held.0 + owned, self.held.1 + ghosts, self.held.2 + 1);
        Ok(StepFacts {
            counters: report.counters,
            max_overlap_ratio: report.max_overlap_ratio,
            warned: !report.overlap_warnings.is_empty(),
        })
    }

    fn projectile(
        &mut self,
        gauge: &ProjectileGauge,
    ) -> Result<(MonitorRow, RigidBody), PenetrationError> {
        let rank = self.run.rank();
        let (row, body, owner) = self.run.from_owner(gauge.index, |part, local| {
            let on_part = ProjectileGauge {
                index: local,
                ..*gauge
            };
            (on_part.row(part), *part.body(local), rank)
        })?;
        if self.projectile_owner.is_some_and(|last| last != owner) {
            self.projectile_owner_changes += 1;
        }
        self.projectile_owner = Some(owner);
        Ok((row, body))
    }

    fn whole(&mut self) -> Result<&Simulation, PenetrationError> {
        self.whole.world = self.run.gather_world()?;
        Ok(&self.whole)
    }

    /// Reduced once at the end of the run (not at every step: a collective per step costs on a loaded
    /// machine).
    fn overlaps(&mut self, max_overlap_ratio: Real, warned: &[bool]) -> (Real, u64) {
        let world = SimpleCommunicator::world();
        let mut largest = 0.0;
        world.all_reduce_into(&max_overlap_ratio, &mut largest, SystemOperation::max());
        let mine: Vec<u8> = warned.iter().map(|&w| u8::from(w)).collect();
        let mut any = vec![0u8; mine.len()];
        world.all_reduce_into(&mine[..], &mut any[..], SystemOperation::max());
        let steps = any.iter().filter(|&&w| w != 0).count() as u64;
        (largest, steps)
    }

    fn agree(&mut self, requested: bool) -> bool {
        let mine = u8::from(requested);
        let mut any = 0u8;
        SimpleCommunicator::world().all_reduce_into(&mine, &mut any, SystemOperation::max());
        any != 0
    }
}
