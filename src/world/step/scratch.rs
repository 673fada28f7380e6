//! The buffers the step reuses from one step to the next.

use std::sync::Arc;

use crate::law::ContactModel;

use super::super::body_inputs;
use super::super::contact_store::ContactKey;
use super::super::parallel::Worker;
use super::super::sleeping;
use super::consensus::RebuildConsensus;
use super::laws::Evaluated;
use super::sphere_kernel;

/// Buffers reused between steps; nothing in them matters after a step.
#[derive(Clone, Debug, Default)]
pub struct StepScratch {
    /// Per-body inputs of stage 3 (written by the drift pass) and the kept candidate list's key; its
    /// summary's anisotropic count (dynamic bodies with unequal principal moments at the last evaluation
    /// of the loads) chooses serial or parallel integration (never a result).
    pub(super) inputs: body_inputs::BodyInputs,
    /// Whether some body has a prescribed motion (its power enters the ledger).
    pub(super) any_prescribed: bool,
    /// The contact model of each material pair with the skips applied.
    pub(super) models: Vec<Option<ContactModel>>,
    pub(super) candidates: Vec<ContactKey>,
    pub(super) evaluated: Vec<Evaluated>,
    /// One per chunk of the parallel stages (see [`super::parallel`]).
    pub(super) workers: Vec<Worker>,
    /// The summed contributions of the frozen contacts (see [`super::sleeping`]).
    pub(super) frozen: sleeping::FrozenLoads,
    /// Per body, what the sphere path of stages 4–5 reads (see [`super::sphere_kernel`]).
    pub(super) spheres: Vec<sphere_kernel::SphereBody>,
    /// Set by stage 6 when it left the per-body force sums to the pass of stages 7–8 (the gather fused
    /// with the second half kick); consumed in the same step.
    pub(super) deferred_gather: bool,
    /// What the check of the time step keeps of the world (see [`super::guard`]).
    pub(super) guard: super::guard::Guard,
    /// The rebuild decision of a world split over processes (none: this world's own).
    pub(super) consensus: Option<Arc<dyn RebuildConsensus>>,
}

impl StepScratch {
    /// Makes stage 3 ask `consensus` whether to rebuild the broad phase (a part of a world split over
    /// processes); `None` restores the world's own decision.
    pub fn set_rebuild_consensus(&mut self, consensus: Option<Arc<dyn RebuildConsensus>>) {
        self.consensus = consensus;
    }
}
