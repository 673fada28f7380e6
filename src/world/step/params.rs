//! The parameters of the step shared by all bodies.

use crate::contact::ContactTolerances;
use crate::dynamics::{RotationScheme, ViscousDamping};
use crate::math::Real;

use super::super::parallel::Parallelism;
use super::super::skips::Skips;
use super::super::sleep_state::SleepParams;
#[cfg(doc)]
use super::super::world::World;
use super::findings::TimeStepCheck;
#[cfg(doc)]
use super::StepReport;

/// Default of [`StepParams::overlap_warning_fraction`]: 0.05. A DEM run with a stiffness that represents
/// the material keeps overlaps below ~1 % of the particle size; 5 % means the stiffness or the time step is
/// wrong for the impact speeds of the scene, well before the contact geometry itself degrades.
pub const DEFAULT_OVERLAP_WARNING_FRACTION: Real = 0.05;

/// Parameters of the step shared by all bodies.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepParams {
    /// Time step Δt (s).
    pub dt: Real,
    /// Rotation scheme of the integrator.
    pub rotation: RotationScheme,
    /// Global viscous damping (paper eq. 6); accounted in the ledger as `dissipated_viscous`.
    pub damping: ViscousDamping,
    /// Tolerances of the contact queries.
    pub tolerances: ContactTolerances,
    /// A contact whose overlap exceeds this fraction of the smaller particle's length scale (bounding
    /// diameter) is reported in [`StepReport::overlap_warnings`].
    pub overlap_warning_fraction: Real,
    /// From which sizes the stages run on several threads (results are identical either way).
    pub parallel: Parallelism,
    /// Work skipped because the scene does not need it (all on by default; see [`crate::world::skips`]).
    pub skips: Skips,
    /// Freezing of bodies at rest (off by default; see [`crate::world::sleeping`]).
    pub sleeping: SleepParams,
    /// Whether the step books the per-contact terms of the energy ledger (damping, friction and
    /// tangential stiffness work; see [`crate::world::energy`]). On by default. Off, the step skips that booking
    /// (a run that only needs trajectories and forces: the speed comparisons with codes that keep no
    /// ledger); bodies, forces and the contact store are the same bits either way, but the ledger's
    /// `dissipated_damping`, `dissipated_friction` and `tangential_stiffness_work` stay where they were, so
    /// [`World::energy`]'s balance no longer closes.
    pub energy_ledger: bool,
    /// What the step does when its check finds the motion too fast for the time step (stop by default;
    /// see `world::step::guard`). Not stored in checkpoints: a run restarted from one checks with the default.
    #[serde(skip)]
    pub time_step_check: TimeStepCheck,
}

impl StepParams {
    /// The step Δt with the paper's rotation scheme, no global damping, default tolerances and overlap
    /// warning fraction.
    pub fn new(dt: Real) -> Self {
        Self {
            dt,
            rotation: RotationScheme::default(),
            damping: ViscousDamping::None,
            tolerances: ContactTolerances::default(),
            overlap_warning_fraction: DEFAULT_OVERLAP_WARNING_FRACTION,
            parallel: Parallelism::default(),
            skips: Skips::default(),
            sleeping: SleepParams::default(),
            energy_ledger: true,
            time_step_check: TimeStepCheck::default(),
        }
    }
}
