//! [`Simulation`]: a built scene ready to run — the world, its step parameters, the time-step derivation,
//! the run's length and outputs. Built by [`super::build`], run by [`super::run`].

use crate::math::{Pose, Real, Rotation};
use crate::world::{StepParams, World};

use super::time_step::TimeStepInfo;

/// A scene ready to run.
///
/// # Example
/// Load a scene file, shorten the run, and run it with the CSV series written every 10 steps:
///
/// ```
/// use polydem::io::csv_series::CsvSeries;
/// use polydem::io::output::{OutputSet, Schedule};
/// use polydem::scene::load_scene;
///
/// let dir = std::env::temp_dir().join(format!("polydem-doctest-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("ball.toml");
/// std::fs::write(&path, r#"
///     [simulation]
///     gravity = [0.0, 0.0, -9.81]
///     end_time = 1.0
///     output_interval = 0.01
///     steps_per_contact = 50
///
///     [[material]]
///     name = "glass"
///     density = 2500.0
///
///     [[interaction]]
///     materials = ["glass", "glass"]
///     law = "linear"
///     normal_stiffness = 1.0e5
///     restitution = 0.5
///     friction = 0.0
///
///     [[shape]]
///     name = "ball"
///     kind = "sphere"
///     radius = 0.01
///
///     [[body]]
///     name = "ball"
///     shape = "ball"
///     material = "glass"
///     position = [0.0, 0.0, 0.05]
///     track = true
///
///     [[wall]]
///     name = "floor"
///     material = "glass"
///     point = [0.0, 0.0, 0.0]
///     normal = [0.0, 0.0, 1.0]
/// "#)?;
/// let mut sim = load_scene(&path)?;
/// sim.set_end_time(0.02)?; // a short run
///
/// let schedule = Schedule {
///     start_step: sim.world.step_index(),
///     last_step: sim.steps,
///     every: Some(10),
///     at_start: true,
///     at_end: true,
/// };
/// let mut outputs = OutputSet::new();
/// outputs.push(CsvSeries::create(&dir, schedule)?);
/// let summary = sim.run_observed(&mut outputs)?;
/// outputs.finish()?;
///
/// assert_eq!(summary.steps, sim.steps);
/// let energy = std::fs::read_to_string(dir.join("energy.csv"))?;
/// // header + the start + a row every 10 steps (the last step is one of them or added)
/// assert!(energy.lines().count() >= 2 + (sim.steps / 10) as usize);
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
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
        self.world.bodies()[i].orientation * self.frames[i].rotation.inverse()
    }
}
