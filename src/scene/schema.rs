//! The typed schema of a scene file (TOML): one struct per table, `deny_unknown_fields` everywhere, and
//! every value that validation may refuse wrapped in [`Spanned`] so that the error can name its line.
//!
//! Only the fields whose absence has an obvious physical meaning are optional (initial velocities, a wall's
//! velocity, the motion kind, tracking, global damping); every material constant and law parameter is
//! required. `docs/scene-format.md` is the user's description of this schema.

use serde::Deserialize;
use toml::Spanned;

/// A 3-vector in the file.
pub type Vec3 = [f64; 3];

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `[simulation]`.
    pub simulation: SimulationSection,
    /// `[[material]]` tables.
    #[serde(default, rename = "material")]
    pub materials: Vec<MaterialSection>,
    /// `[[interaction]]` tables.
    #[serde(default, rename = "interaction")]
    pub interactions: Vec<InteractionSection>,
    /// `[[shape]]` tables.
    #[serde(default, rename = "shape")]
    pub shapes: Vec<ShapeSection>,
    /// `[[body]]` tables.
    #[serde(default, rename = "body")]
    pub bodies: Vec<BodySection>,
    /// `[[wall]]` tables.
    #[serde(default, rename = "wall")]
    pub walls: Vec<WallSection>,
    /// `[[box]]` tables.
    #[serde(default, rename = "box")]
    pub boxes: Vec<BoxSection>,
    /// `[[body_file]]` tables.
    #[serde(default, rename = "body_file")]
    pub body_files: Vec<BodyFileSection>,
}

/// `[simulation]`: time stepping, gravity, output.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSection {
    /// Gravitational acceleration (m/s²).
    pub gravity: Spanned<Vec3>,
    /// Simulated duration (s).
    pub end_time: Spanned<f64>,
    /// Interval between output rows (s); rounded to a whole number of steps (at least one).
    pub output_interval: Spanned<f64>,
    /// The most steps the run may take (end_time / Δt); absent = `crate::scene::DEFAULT_MAX_STEPS`. A
    /// longer run is refused unless this is raised.
    pub max_steps: Option<Spanned<u64>>,
    /// A given time step (s), refused when above the stability limit. Exclusive with `steps_per_contact`.
    pub time_step: Option<Spanned<f64>>,
    /// N in Δt = t_c,min / N (see the docs for t_c). Exclusive with `time_step`.
    pub steps_per_contact: Option<Spanned<f64>>,
    /// Impact speed (m/s) at which the contact time and stability of nonlinear laws are evaluated;
    /// required when some law has an exponent other than 1.
    pub characteristic_speed: Option<Spanned<f64>>,
    /// Rate α (1/s) of a global mass-proportional viscous damping c = α m (paper eq. 6); absent = none.
    pub viscous_damping_rate: Option<Spanned<f64>>,
    /// Verlet skin of the broad phase (m); absent = 0.2 × the smallest bounding radius.
    pub skin: Option<Spanned<f64>>,
    /// Overlap that a polyhedron–wall contact hands to the law: `"smoothed"` (default) or
    /// `"deepest_vertex"` (see `crate::contact::wall_depth`).
    pub wall_depth: Option<Spanned<String>>,
    /// Band h of the smoothed wall depth as a fraction of the body's bounding diameter; absent = 1e-4.
    pub wall_depth_band: Option<Spanned<f64>>,
    /// Overlap that a polyhedron–polyhedron contact hands to the law: `"smoothed"` (default) or `"exact"`
    /// (see `crate::contact::pair_smoothing`).
    pub pair_smoothing: Option<Spanned<String>>,
    /// Band h of the smoothed pair overlap as a fraction of the smaller bounding diameter; absent = 1e-4.
    pub pair_smoothing_band: Option<Spanned<f64>>,
    /// Whether the step books the per-contact terms of the energy ledger; absent = true (see
    /// `crate::world::StepParams::energy_ledger`).
    pub energy_ledger: Option<Spanned<bool>>,
    /// What the run does when the motion outruns the time step (`crate::world::TimeStepCheck`):
    /// `"stop"` (absent = stop), `"warn"` or `"off"`.
    pub time_step_check: Option<Spanned<String>>,
}

/// `[[material]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSection {
    /// Name the interactions refer to.
    pub name: Spanned<String>,
    /// Density (kg/m³).
    pub density: Spanned<f64>,
    /// Young's modulus E (Pa); required by the `hertz_mindlin` law.
    pub young_modulus: Option<Spanned<f64>>,
    /// Poisson's ratio ν (−1 < ν ≤ 0.5); required by the `hertz_mindlin` law.
    pub poisson_ratio: Option<Spanned<f64>>,
}

/// `[[interaction]]`: the contact law of a pair of materials.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InteractionSection {
    /// The two material names of the pair (either order).
    pub materials: Spanned<[String; 2]>,
    /// `"linear"` (f_n = k_n δ), `"power"` (f_n = k_n δ^n) or `"hertz_mindlin"` (from the materials' E, ν).
    pub law: Spanned<String>,
    /// k_n (N/m^n); linear and power laws only.
    pub normal_stiffness: Option<Spanned<f64>>,
    /// n (power law only; 1 ≤ n ≤ 3).
    pub exponent: Option<Spanned<f64>>,
    /// Coefficient of restitution e, 0 < e ≤ 1; exclusive with `normal_damping`.
    pub restitution: Option<Spanned<f64>>,
    /// A constant normal dashpot c_n (N s/m), linear law only; exclusive with `restitution`.
    pub normal_damping: Option<Spanned<f64>>,
    /// k_t (N/m); linear and power laws, required when `friction` > 0.
    pub tangential_stiffness: Option<Spanned<f64>>,
    /// Coulomb friction coefficient μ ≥ 0.
    pub friction: Spanned<f64>,
    /// `hertz_mindlin` only: tangential dashpot while sticking; absent = true (LIGGGHTS' default).
    pub tangential_damping: Option<Spanned<bool>>,
    /// The total normal force is never attractive; absent = false (LIGGGHTS' default).
    pub limit_force: Option<Spanned<bool>>,
    /// How the tangential spring follows the turning normal: `"exact"` (rotation; absent = exact, the
    /// engine's rule) or `"projection"` (its normal part removed, as LIGGGHTS; see
    /// `polydem::law::SpringRotation`). No effect without a tangential spring.
    pub spring_rotation: Option<Spanned<String>>,
}

/// `[[shape]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeSection {
    /// Name the bodies and body files refer to.
    pub name: Spanned<String>,
    /// `"box"`, `"sphere"`, `"polyhedron"` or `"ellipsoid"`.
    pub kind: Spanned<String>,
    /// Box: half extents (m).
    pub half_extents: Option<Spanned<Vec3>>,
    /// Sphere: radius (m).
    pub radius: Option<Spanned<f64>>,
    /// Polyhedron: points (m) whose convex hull is the shape (≥ 4, not coplanar).
    pub points: Option<Spanned<Vec<Vec3>>>,
    /// Ellipsoid: semi-axes (a, b, c) along the shape's x, y, z (m).
    pub semi_axes: Option<Spanned<Vec3>>,
}

/// `[[body]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySection {
    /// Name of the body.
    pub name: Spanned<String>,
    /// Name of its `[[shape]]`.
    pub shape: Spanned<String>,
    /// Name of its `[[material]]`.
    pub material: Spanned<String>,
    /// Where the origin of the shape's own coordinates goes (m).
    pub position: Spanned<Vec3>,
    /// Unit quaternion `[w, x, y, z]` turning the shape's coordinates into the world; exclusive with
    /// `axis_angle`; absent = identity.
    pub orientation: Option<Spanned<[f64; 4]>>,
    /// Rotation vector (axis × angle, rad); exclusive with `orientation`.
    pub axis_angle: Option<Spanned<Vec3>>,
    /// Velocity of the centre of mass (m/s); absent = zero.
    pub velocity: Option<Spanned<Vec3>>,
    /// Angular velocity (rad/s, world frame); absent = zero.
    pub angular_velocity: Option<Spanned<Vec3>>,
    /// `"dynamic"` (absent), `"fixed"` or `"prescribed"` (moves with `velocity`, `angular_velocity`).
    pub motion: Option<Spanned<String>>,
    /// Write this body to `bodies.csv`; absent = false.
    pub track: Option<bool>,
}

/// `[[wall]]`: the half-space behind a plane.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallSection {
    /// Name of the wall.
    pub name: Spanned<String>,
    /// Name of its `[[material]]`.
    pub material: Spanned<String>,
    /// A point of the plane (m).
    pub point: Spanned<Vec3>,
    /// Outward normal, pointing to the free side where the bodies are (normalised on reading).
    pub normal: Spanned<Vec3>,
    /// Prescribed velocity (m/s); absent = fixed.
    pub velocity: Option<Spanned<Vec3>>,
}

/// `[[box]]`: an axis-aligned box of walls facing inwards, one wall per closed face.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSection {
    /// Name of the box (its walls are named after it and the face).
    pub name: Spanned<String>,
    /// Material of its walls.
    pub material: Spanned<String>,
    /// The lower corner (m).
    pub min: Spanned<Vec3>,
    /// The upper corner (m).
    pub max: Spanned<Vec3>,
    /// Faces without a wall, among `"x-"`, `"x+"`, `"y-"`, `"y+"`, `"z-"`, `"z+"`; absent = none.
    pub open: Option<Spanned<Vec<String>>>,
    /// One face that moves with `velocity`; absent = every face fixed.
    pub moving_face: Option<Spanned<String>>,
    /// Prescribed velocity of `moving_face` (m/s).
    pub velocity: Option<Spanned<Vec3>>,
}

/// `[[body_file]]`: bodies from a CSV file: spheres (a `radius` column) or the scene's `[[shape]]`s placed
/// by a pose (a `shape` column); see [`crate::scene::body_file`].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyFileSection {
    /// The CSV file, relative to the scene file's directory.
    pub path: Spanned<String>,
    /// Material of the bodies.
    pub material: Spanned<String>,
    /// Body names are this prefix followed by the `id` column (or the row number).
    pub name_prefix: Spanned<String>,
    /// `"file"` (the vx, vy, vz columns, and wx, wy, wz of a shape table) or `"zero"`; absent = `"file"`
    /// when the columns exist.
    pub velocities: Option<Spanned<String>>,
    /// Write these bodies to `bodies.csv`; absent = false.
    pub track: Option<bool>,
}
