//! The experiment's parameters as data: Table 1's contact parameters, the rock, layer, packing, impact and
//! projectile sections of a TOML file (`scenes/rockfill/paper.toml` is the full-scale experiment with the
//! source of every value; `scenes/rockfill/quick.toml` the scaled quick variant). Every field is required
//! (no silent defaults for physical constants) and unknown fields are refused.
//!
//! [`ExperimentConfig::contact_models`] turns Table 1 into the engine's slot-composed laws: linear normal
//! law f_n = k_n δ, restitution damping for e_r (rock–rock, rock–wall) and e_b (rock–projectile), constant
//! tangential spring k_s with Coulomb cap f.

use std::path::Path;

use super::projectile::ProjectileParams;
use polydem::law::{ContactModel, DampingLaw, LawError, NormalLaw, TangentialLaw};
use polydem::math::Real;

/// The default [`RunLimits::max_rocks`]: 200 000 rocks, five times the paper's layer at its smallest size
/// (about 37 000 rocks at 100 mm), about [`super::limits::BYTES_PER_ROCK`] × 200 000 = 2.4 GB.
pub const DEFAULT_MAX_ROCKS: usize = 200_000;

/// The default [`RunLimits::max_steps`] of each stage: 10^7 steps. The paper's runs take about 3·10^5
/// packing steps and 5 000 penetration steps at 100 mm; the penetration keeps one monitor row per step
/// (10^7 rows are 1.4 GB).
pub const DEFAULT_MAX_STEPS: u64 = 10_000_000;

/// The size limits of a run; the experiment file's optional `[limits]` section (absent: the defaults).
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunLimits {
    /// The most rocks generation may make (the seed count of eq. 28).
    pub max_rocks: usize,
    /// The most steps of the packing (all its stages) and of the penetration run, each.
    pub max_steps: u64,
}

impl Default for RunLimits {
    fn default() -> Self {
        Self {
            max_rocks: DEFAULT_MAX_ROCKS,
            max_steps: DEFAULT_MAX_STEPS,
        }
    }
}

/// Why a configuration was refused.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Parse { path: String, message: String },
    #[error("{path}: {field} = {value} is invalid: {reason}")]
    Invalid {
        path: String,
        field: &'static str,
        value: Real,
        reason: &'static str,
    },
    #[error("contact law: {0}")]
    Law(#[from] LawError),
}

/// Table 1 of the paper.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ContactParams {
    /// k_n (N/m), linear normal law.
    pub normal_stiffness: Real,
    /// k_s (N/m).
    pub tangential_stiffness: Real,
    /// Coefficient of friction f.
    pub friction: Real,
    /// e_r: rock–rock (and rock–wall).
    pub restitution_rocks: Real,
    /// e_b: rock–projectile.
    pub restitution_projectile: Real,
}

/// The rocks.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RockParams {
    /// kg/m³.
    pub density: Real,
    /// Mean size (m).
    pub mean_size: Real,
    pub sigma_fraction: Real,
    pub range_fraction: Real,
    pub seed: u64,
}

/// The layer: x along the flight path from the left face at x = 0, y across, z up from the floor.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LayerParams {
    pub length: Real,
    pub width: Real,
    pub height: Real,
}

/// Deposition and compaction.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PackingParams {
    /// Height of the region the rocks are generated in, over the layer height.
    pub generation_height_factor: Real,
    /// Δt = t_c,min / steps_per_contact.
    pub steps_per_contact: Real,
    /// Global mass-proportional damping rate α (1/s) during deposition and compaction.
    pub viscous_rate: Real,
    /// Deposition ends when every rock is slower than this (m/s).
    pub settle_speed: Real,
    pub max_deposition_time: Real,
    /// Speed of the top wall during compaction (m/s).
    pub compaction_speed: Real,
    /// Pressure (Pa) at which the top wall's servo stops it (see [`super::packing`]).
    pub compaction_pressure: Real,
    /// Time with the top wall stopped after compaction (s).
    pub hold_time: Real,
    /// Geometric pre-collapse before the drop ([`super::collapse`]): the gap left under every rock, as a
    /// fraction of the mean rock size. Absent: the rocks fall from where they were generated (the procedure of
    /// the runs made before the collapse existed). A packing-procedure choice; the paper fixes none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub collapse_gap: Option<Real>,
    /// Deposition also waits until the rocks' kinetic energy is below this fraction of Σ m g d̄ (the work of
    /// lifting every rock by one mean size d̄). Absent: only the speed criterion (`settle_speed`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_kinetic_fraction: Option<Real>,
    /// Δt = t_c,min / this during packing only (deposition, compaction, hold); the penetration keeps
    /// `steps_per_contact`. Absent: packing uses `steps_per_contact` too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub packing_steps_per_contact: Option<Real>,
    /// Deposition damping: `viscous` (the global mass-proportional `viscous_rate` on every rock, which also
    /// slows the free fall: terminal speed g / α) or `local` (Cundall's non-viscous local damping with the
    /// coefficient `local_damping`, only on rocks that touch something, so a rock in free flight falls
    /// undamped; see [`super::packing::local_damping`]). Absent: `viscous`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deposition_damping: Option<DepositionDamping>,
    /// Coefficient α of the local damping, 0 < α < 1 (YADE's default for quasi-static packing is 0.2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub local_damping: Option<Real>,
    /// Initial downward speed v0 of every rock (m/s): a cloud in free fall moves rigidly, so this is the
    /// loose sample as it would be after falling v0/g from v0²/(2g) higher, caught when its lowest rock is
    /// where it was generated (under the global viscous damping, v0 = g/α starts the cloud at its terminal
    /// speed). The rock count, sizes and arrangement (eq. 28/29) are unchanged. Absent: the rocks start at rest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drop_speed: Option<Real>,
    /// Density (mass) scaling during packing only: the rocks pack with density s ρ (mass and inertia × s), so
    /// the contact time and the packing Δt grow by √s while the gravity-driven motion (fall, viscous
    /// damping, settling) keeps its physical time; the compaction cap is scaled by s with the weights, so the
    /// packing is the one of a bed of true mass with the stiffness k/s. After the hold the true density is
    /// restored and the bed is relaxed for `restore_time` at the true Δt (see [`super::packing`]). Absent:
    /// the rocks pack at their true density.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub packing_density_scale: Option<Real>,
    /// Time (s) at the true density after the scaled packing, with the top wall backed off to the force it
    /// would carry at the true weights; required with `packing_density_scale`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restore_time: Option<Real>,
}

/// The damping of the deposition stage (see [`PackingParams::deposition_damping`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DepositionDamping {
    Viscous,
    Local,
}

/// The impact.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactParams {
    /// m/s.
    pub speed: Real,
    /// Time at which the tip reaches the left face (s).
    pub arrival_time: Real,
    /// Run length limit (s).
    pub max_time: Real,
    /// Projectile travel per step over the mean rock size.
    pub travel_per_step: Real,
    /// A rock is disturbed when its displacement exceeds this fraction of the mean size.
    pub disturbed_threshold: Real,
}

/// Sleeping in the experiment's runs ([`polydem::world::sleeping`]): a numerical device, not a physical
/// parameter, so the section and each of its keys may be left out; the defaults are the engine's thresholds
/// and sleeping off, which reproduces the runs made before sleeping existed.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct SleepingConfig {
    /// Penetration run: the packed bed starts asleep, each rock with the load of the bed's last evaluation
    /// as its rest load, and a rock wakes when the projectile (or a woken neighbour, or the removal of the
    /// left and right walls) changes its load by more than `rest_force` of its weight.
    pub penetration: bool,
    /// Packing: rocks at rest fall asleep during deposition and hold (the moving top wall wakes the rocks
    /// it touches, and their neighbours through their loads).
    pub packing: bool,
    /// [`polydem::world::SleepParams::rest_speed`] (fraction of √(|g| d)).
    pub rest_speed: Real,
    /// [`polydem::world::SleepParams::rest_force`] (fraction of the weight).
    pub rest_force: Real,
    /// [`polydem::world::SleepParams::steps`].
    pub steps: u32,
    /// [`polydem::world::SleepParams::wake_contact_fraction`]: in a compacted bed every contact carries many
    /// rock weights, so a threshold of a fraction of the weight is a fraction of a per mille of the contact
    /// forces, and the explicit step's one-contact-per-step precursor of any disturbance then wakes the whole
    /// bed within tens of steps.
    pub wake_contact_fraction: Real,
}

impl Default for SleepingConfig {
    fn default() -> Self {
        let engine = polydem::world::SleepParams::default();
        Self {
            penetration: false,
            packing: false,
            rest_speed: engine.rest_speed,
            rest_force: engine.rest_force,
            steps: engine.steps,
            wake_contact_fraction: engine.wake_contact_fraction,
        }
    }
}

impl SleepingConfig {
    /// The engine's sleeping parameters, on when `enabled`.
    pub fn params(&self, enabled: bool) -> polydem::world::SleepParams {
        polydem::world::SleepParams {
            enabled,
            rest_speed: self.rest_speed,
            rest_force: self.rest_force,
            steps: self.steps,
            wake_contact_fraction: self.wake_contact_fraction,
        }
    }
}

/// Everything the experiment needs.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentConfig {
    pub contact: ContactParams,
    pub rock: RockParams,
    pub layer: LayerParams,
    pub packing: PackingParams,
    pub impact: ImpactParams,
    pub projectile: ProjectileParams,
    /// Optional (see [`SleepingConfig`]).
    #[serde(default)]
    pub sleeping: SleepingConfig,
    /// Optional: the most rocks and steps the run may take (see [`RunLimits`]).
    #[serde(default)]
    pub limits: RunLimits,
}

/// The full-scale experiment (the file `scenes/rockfill/paper.toml`, compiled in).
pub const PAPER_TOML: &str = include_str!("../../../scenes/rockfill/paper.toml");
/// The quick variant (the file `scenes/rockfill/quick.toml`, compiled in).
pub const QUICK_TOML: &str = include_str!("../../../scenes/rockfill/quick.toml");

/// The contact models of the experiment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactModels {
    /// Rock–rock, rock–wall (and projectile–wall, which does not occur in the run).
    pub rocks: ContactModel,
    /// Rock–projectile.
    pub projectile: ContactModel,
}

impl ExperimentConfig {
    /// Parses and checks a configuration; `path` names the source in errors.
    pub fn parse(source: &str, path: &str) -> Result<Self, ConfigError> {
        let config: Self = toml::from_str(source).map_err(|e| ConfigError::Parse {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        config.check(path)?;
        Ok(config)
    }

    /// Reads a configuration file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let name = path.display().to_string();
        let source = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: name.clone(),
            source,
        })?;
        Self::parse(&source, &name)
    }

    /// The compiled-in full-scale experiment.
    pub fn paper() -> Self {
        Self::parse(PAPER_TOML, "scenes/rockfill/paper.toml").expect("the shipped file is valid")
    }

    /// The compiled-in quick variant.
    pub fn quick() -> Self {
        Self::parse(QUICK_TOML, "scenes/rockfill/quick.toml").expect("the shipped file is valid")
    }

    fn check(&self, path: &str) -> Result<(), ConfigError> {
        let invalid = |field, value, reason| ConfigError::Invalid {
            path: path.to_owned(),
            field,
            value,
            reason,
        };
        let fraction = |v: Real| v.is_finite() && v > 0.0 && v < 1.0;
        let positive = |v: Real| v.is_finite() && v > 0.0;
        let non_negative = |v: Real| v.is_finite() && v >= 0.0;
        if let Some((field, v)) = first_bad(&self.optional_fractions(), fraction) {
            return Err(invalid(field, v, "must lie strictly between 0 and 1"));
        }
        if let Some((field, v)) = first_bad(&self.optional_positives(), positive) {
            return Err(invalid(field, v, "must be finite and positive"));
        }
        if let Some((field, reason)) = self.missing_companion() {
            return Err(invalid(field, Real::NAN, reason));
        }
        let wake = self.sleeping.wake_contact_fraction;
        if !non_negative(wake) {
            let field = "sleeping.wake_contact_fraction";
            return Err(invalid(field, wake, "must be finite and non-negative"));
        }
        if let Some((field, v)) = first_bad(&self.positives().map(some), positive) {
            return Err(invalid(field, v, "must be finite and positive"));
        }
        if let Some((field, v)) = first_bad(&self.non_negatives().map(some), non_negative) {
            return Err(invalid(field, v, "must be finite and non-negative"));
        }
        if self.limits.max_rocks == 0 || self.limits.max_steps == 0 {
            return Err(invalid(
                "limits.max_rocks / limits.max_steps",
                0.0,
                "must be at least 1",
            ));
        }
        if self.packing.generation_height_factor < 1.0 {
            return Err(invalid(
                "packing.generation_height_factor",
                self.packing.generation_height_factor,
                "must be at least 1 (rocks are generated above the layer and fall into it)",
            ));
        }
        self.contact_models()?;
        Ok(())
    }

    /// The fields that must be finite and positive.
    fn positives(&self) -> [(&'static str, Real); 15] {
        let (r, l, p, i) = (&self.rock, &self.layer, &self.packing, &self.impact);
        [
            ("rock.density", r.density),
            ("rock.mean_size", r.mean_size),
            ("layer.length", l.length),
            ("layer.width", l.width),
            ("layer.height", l.height),
            (
                "packing.generation_height_factor",
                p.generation_height_factor,
            ),
            ("packing.steps_per_contact", p.steps_per_contact),
            ("packing.settle_speed", p.settle_speed),
            ("packing.max_deposition_time", p.max_deposition_time),
            ("packing.compaction_speed", p.compaction_speed),
            ("packing.compaction_pressure", p.compaction_pressure),
            ("impact.speed", i.speed),
            ("impact.max_time", i.max_time),
            ("impact.travel_per_step", i.travel_per_step),
            ("impact.disturbed_threshold", i.disturbed_threshold),
        ]
    }

    /// The fields that must be finite and non-negative.
    fn non_negatives(&self) -> [(&'static str, Real); 5] {
        [
            ("packing.viscous_rate", self.packing.viscous_rate),
            ("packing.hold_time", self.packing.hold_time),
            ("impact.arrival_time", self.impact.arrival_time),
            ("sleeping.rest_speed", self.sleeping.rest_speed),
            ("sleeping.rest_force", self.sleeping.rest_force),
        ]
    }

    /// The optional fields that, when given, must lie strictly between 0 and 1.
    fn optional_fractions(&self) -> [(&'static str, Option<Real>); 3] {
        let p = &self.packing;
        [
            ("packing.collapse_gap", p.collapse_gap),
            ("packing.settle_kinetic_fraction", p.settle_kinetic_fraction),
            ("packing.local_damping", p.local_damping),
        ]
    }

    /// The optional fields that, when given, must be finite and positive.
    fn optional_positives(&self) -> [(&'static str, Option<Real>); 4] {
        let p = &self.packing;
        [
            (
                "packing.packing_steps_per_contact",
                p.packing_steps_per_contact,
            ),
            ("packing.drop_speed", p.drop_speed),
            ("packing.packing_density_scale", p.packing_density_scale),
            ("packing.restore_time", p.restore_time),
        ]
    }

    /// An optional field another one requires, when it is missing: (the field, why).
    fn missing_companion(&self) -> Option<(&'static str, &'static str)> {
        let p = &self.packing;
        if p.deposition_damping == Some(DepositionDamping::Local) && p.local_damping.is_none() {
            return Some((
                "packing.local_damping",
                "must be given when deposition_damping = \"local\"",
            ));
        }
        if p.packing_density_scale.is_some() && p.restore_time.is_none() {
            return Some((
                "packing.restore_time",
                "must be given with packing_density_scale",
            ));
        }
        None
    }

    /// Table 1 as the engine's laws (see the module docs).
    pub fn contact_models(&self) -> Result<ContactModels, ConfigError> {
        let c = &self.contact;
        let normal = NormalLaw::linear(c.normal_stiffness)?;
        let tangential = TangentialLaw::spring(c.tangential_stiffness, c.friction)?;
        Ok(ContactModels {
            rocks: ContactModel {
                normal,
                damping: DampingLaw::from_restitution(1.0, c.restitution_rocks)?,
                tangential,
            },
            projectile: ContactModel {
                normal,
                damping: DampingLaw::from_restitution(1.0, c.restitution_projectile)?,
                tangential,
            },
        })
    }
}

/// The first field whose value is given and fails `ok`.
fn first_bad(
    fields: &[(&'static str, Option<Real>)],
    ok: impl Fn(Real) -> bool,
) -> Option<(&'static str, Real)> {
    fields
        .iter()
        .find_map(|&(field, value)| value.filter(|&v| !ok(v)).map(|v| (field, v)))
}

/// A required field as a given optional one.
fn some((field, value): (&'static str, Real)) -> (&'static str, Option<Real>) {
    (field, Some(value))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_files_parse_and_carry_table_1() {
        let p = ExperimentConfig::paper();
        assert_eq!(
            (
                p.contact.normal_stiffness,
                p.contact.tangential_stiffness,
                p.contact.friction
            ),
            (2.0e7, 1.0e7, 0.2)
        );
        assert_eq!(
            (
                p.contact.restitution_rocks,
                p.contact.restitution_projectile
            ),
            (0.4, 0.99)
        );
        let q = ExperimentConfig::quick();
        assert_eq!(q.contact, p.contact, "the quick variant keeps Table 1");
    }

    #[test]
    fn unknown_and_invalid_fields_are_refused() {
        let bad = PAPER_TOML.replace("friction = 0.2", "friction = 0.2\nfriction_typo = 1");
        assert!(matches!(
            ExperimentConfig::parse(&bad, "x"),
            Err(ConfigError::Parse { .. })
        ));
        let bad = PAPER_TOML.replace("density = 2650.0", "density = -1.0");
        assert!(matches!(
            ExperimentConfig::parse(&bad, "x"),
            Err(ConfigError::Invalid { .. })
        ));
    }

    /// The field `check` names for one bad value of each kind, and its reason.
    #[test]
    fn each_kind_of_bad_value_names_its_field() {
        type Edit = fn(&mut ExperimentConfig);
        let cases: [(Edit, &str, &str); 9] = [
            (
                |c| c.packing.collapse_gap = Some(1.0),
                "packing.collapse_gap",
                "strictly between 0 and 1",
            ),
            (
                |c| c.packing.drop_speed = Some(0.0),
                "packing.drop_speed",
                "finite and positive",
            ),
            (
                |c| {
                    c.packing.deposition_damping = Some(DepositionDamping::Local);
                    c.packing.local_damping = None;
                },
                "packing.local_damping",
                "must be given",
            ),
            (
                |c| {
                    c.packing.packing_density_scale = Some(4.0);
                    c.packing.restore_time = None;
                },
                "packing.restore_time",
                "must be given",
            ),
            (
                |c| c.sleeping.wake_contact_fraction = -1.0,
                "sleeping.wake_contact_fraction",
                "non-negative",
            ),
            (
                |c| c.impact.travel_per_step = Real::NAN,
                "impact.travel_per_step",
                "finite and positive",
            ),
            (
                |c| c.packing.hold_time = -0.1,
                "packing.hold_time",
                "non-negative",
            ),
            (
                |c| c.limits.max_steps = 0,
                "limits.max_rocks / limits.max_steps",
                "at least 1",
            ),
            (
                |c| c.packing.generation_height_factor = 0.5,
                "packing.generation_height_factor",
                "at least 1",
            ),
        ];
        for (edit, expected_field, expected_reason) in cases {
            let mut config = ExperimentConfig::quick();
            edit(&mut config);
            match config.check("x") {
                Err(ConfigError::Invalid { field, reason, .. }) => {
                    assert_eq!(field, expected_field, "reason: {reason}");
                    assert!(
                        reason.contains(expected_reason),
                        "{field}: reason '{reason}', expected it to say '{expected_reason}'"
                    );
                }
                other => panic!("{expected_field}: expected Invalid, got {other:?}"),
            }
        }
    }
}
