//! [`Simulation`]: a built scene ready to run — the world, its step parameters, the time-step derivation,
//! the run's length and outputs. Built by [`super::build`], run by [`super::run`].

use crate::math::{Pose, Real, Rotation};
use crate::world::{StepParams, World};

use super::time_step::TimeStepInfo;

/// A scene ready to run.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Simulation {
    /// The world: bodies, walls, materials, contacts.
    pub world: World,
    /// Parameters of the step.
    pub params: StepParams,
    /// How the time step was chosen.
    pub time_step: TimeStepInfo,
    /// Simulated duration (s).
    pub end_time: Real,
    /// Number of steps that covers `end_time`.
    pub steps: u64,
    /// Output every this many steps.
    pub output_every: u64,
    /// Bodies written to `bodies.csv`, in file order.
    pub tracked: Vec<usize>,
    /// For each body, the pose of its principal frame in the shape's own (input) frame: the body's
    /// orientation as the user gave it is `orientation · frame.rotation⁻¹`.
    pub frames: Vec<Pose>,
}

impl Simulation {
    /// The orientation of body `i`'s own (input) frame, as the scene gave it.
    pub fn input_orientation(&self, i: usize) -> Rotation {
        self.world.bodies[i].orientation * self.frames[i].rotation.inverse()
    }
}

/// The number of steps of size `dt` that covers `end_time` (at least one; an end time within 1e-9 steps
/// of a whole number of steps is not rounded up by one more).
pub(crate) fn steps_to(end_time: Real, dt: Real) -> u64 {
    (end_time / dt - 1e-9).ceil().max(1.0) as u64
}
