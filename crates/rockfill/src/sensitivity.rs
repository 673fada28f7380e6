//! One-at-a-time sensitivity of the penetration to the contact parameters of Table 1, from one saved bed.
//!
//! The paper (§4.2) states, without figures, that the two stiffnesses and the friction coefficient change
//! the penetration little and the restitution coefficient changes it much. This driver measures that for
//! our model: it runs the penetration of one packed bed with the experiment file's parameters (the base),
//! then once for each value of each varied parameter with every other parameter at the file's value. All runs start from the
//! same bed, so the packing does not change between them (a bed read from its checkpoint takes the file's
//! contact laws, [`super::experiment`]); the rocks' density cannot vary (it set the bed's weights).
//!
//! Varied parameters ([`Parameter`]): the five entries of the file's `[contact]` section, and
//! `contact.stiffness_factor`, a factor on both k_n and k_s (the paper names the two stiffnesses together).
//!
//! Writes into OUT: one folder per run (`base`, `<parameter>_<value>`: `monitors.csv`, `summary.txt`,
//! `section.svg`, as the study's runs), `sensitivity.csv` (one row per run, [`SensitivityRun::CSV_HEADER`])
//! and `sensitivity.md` (the table, with each run's change of the residual velocity against the base),
//! both rewritten after every run.

use std::fmt::Write as _;
use std::path::PathBuf;

use super::config::ExperimentConfig;
use super::study::{csv_text, has_bed, run_one, StudyError, StudyRun};
use polydem::math::Real;

/// A contact parameter the driver can vary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameter {
    /// A factor on both `normal_stiffness` and `tangential_stiffness`.
    StiffnessFactor,
    NormalStiffness,
    TangentialStiffness,
    Friction,
    RestitutionRocks,
    RestitutionProjectile,
}

impl Parameter {
    pub const ALL: [Parameter; 6] = [
        Parameter::StiffnessFactor,
        Parameter::NormalStiffness,
        Parameter::TangentialStiffness,
        Parameter::Friction,
        Parameter::RestitutionRocks,
        Parameter::RestitutionProjectile,
    ];

    /// The key on the command line and in the outputs (the file's `[contact]` names).
    pub fn key(self) -> &'static str {
        match self {
            Parameter::StiffnessFactor => "contact.stiffness_factor",
            Parameter::NormalStiffness => "contact.normal_stiffness",
            Parameter::TangentialStiffness => "contact.tangential_stiffness",
            Parameter::Friction => "contact.friction",
            Parameter::RestitutionRocks => "contact.restitution_rocks",
            Parameter::RestitutionProjectile => "contact.restitution_projectile",
        }
    }

    /// The parameter of `key` (with or without the `contact.` prefix).
    pub fn parse(key: &str) -> Result<Self, String> {
        let full = if key.starts_with("contact.") {
            key.to_owned()
        } else {
            format!("contact.{key}")
        };
        Self::ALL.into_iter().find(|p| p.key() == full).ok_or_else(|| {
            let keys: Vec<&str> = Self::ALL.iter().map(|p| p.key()).collect();
            format!(
                "unknown parameter '{key}': one of {} (the rock density cannot vary on a packed bed)",
                keys.join(", ")
            )
        })
    }

    /// `base` with the parameter set to `value`, checked: the contact laws must accept it.
    pub fn apply(self, base: &ExperimentConfig, value: Real) -> Result<ExperimentConfig, String> {
        let mut config = *base;
        let c = &mut config.contact;
        match self {
            Parameter::StiffnessFactor => {
                if !(value.is_finite() && value > 0.0) {
                    return Err(format!("{} = {value}: must be positive", self.key()));
                }
                c.normal_stiffness *= value;
                c.tangential_stiffness *= value;
            }
            Parameter::NormalStiffness => c.normal_stiffness = value,
            Parameter::TangentialStiffness => c.tangential_stiffness = value,
            Parameter::Friction => c.friction = value,
            Parameter::RestitutionRocks => c.restitution_rocks = value,
            Parameter::RestitutionProjectile => c.restitution_projectile = value,
        }
        config
            .contact_models()
            .map_err(|e| format!("{} = {value}: {e}", self.key()))?;
        Ok(config)
    }
}

/// One varied parameter and its values: `KEY=V1,V2,...` on the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct Variation {
    pub parameter: Parameter,
    pub values: Vec<Real>,
}

impl Variation {
    /// Parses `KEY=V1,V2,...`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (key, values) = text.split_once('=').ok_or_else(|| {
            format!("'{text}': expected KEY=V1,V2,... (e.g. contact.friction=0,0.4)")
        })?;
        let parameter = Parameter::parse(key.trim())?;
        let values = values
            .split(',')
            .map(|v| {
                let v = v.trim();
                v.parse::<Real>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("'{text}': '{v}' is not a finite number"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self { parameter, values })
    }
}

/// What to run.
#[derive(Clone, Debug)]
pub struct SensitivityParams {
    /// The experiment (size and seed as the bed was packed: they set the time step and the disturbed
    /// zone's unit).
    pub base: ExperimentConfig,
    /// The saved bed every run starts from.
    pub bed: PathBuf,
    pub variations: Vec<Variation>,
    pub out: PathBuf,
    /// A name for the provenance line (the experiment file).
    pub label: String,
}

/// One run: the parameter and value it varied (none for the base) and its figures.
#[derive(Clone, Debug, PartialEq)]
pub struct SensitivityRun {
    pub parameter: Option<Parameter>,
    pub value: Real,
    pub run: StudyRun,
    /// Steps of the penetration, the kinetic energy the projectile lost and the energy the contacts
    /// dissipated by damping and by friction (J).
    pub steps: u64,
    pub energy_lost: Real,
    pub damping: Real,
    pub friction: Real,
}

impl SensitivityRun {
    pub const CSV_HEADER: &'static str = "parameter,value,exited,steps,penetration_s,residual_speed,velocity_deflection_deg,axis_deflection_deg,max_axis_deflection_deg,disturbed_width_sizes,resistance_mean_n,resistance_cv_window,energy_lost_j,damping_j,friction_j,max_overlap_ratio,ledger_balance";

    /// The folder name of the run.
    pub fn label(&self) -> String {
        run_label(self.parameter, self.value)
    }

    pub fn csv_row(&self) -> String {
        let r = &self.run;
        format!(
            "{},{},{},{},{:.3},{:.3},{:.4},{:.4},{:.4},{:.3},{:.6e},{:.4},{:.5e},{:.5e},{:.5e},{:.4},{:.3e}",
            self.parameter.map_or("base", Parameter::key),
            self.value,
            r.exited,
            self.steps,
            r.penetration_s,
            r.residual_speed,
            r.velocity_deflection,
            r.axis_deflection,
            r.max_axis_deflection,
            r.disturbed_width_sizes,
            r.resistance_mean,
            r.resistance_cv_window,
            self.energy_lost,
            self.damping,
            self.friction,
            r.max_overlap_ratio,
            r.ledger_balance
        )
    }
}

/// Runs the base, then every value of every variation, from the same bed; `progress` gets one line per
/// event worth showing. Every value is checked before the first run.
pub fn run_sensitivity(
    params: &SensitivityParams,
    progress: &mut dyn FnMut(String),
) -> Result<Vec<SensitivityRun>, StudyError> {
    if !has_bed(&params.bed) {
        return Err(StudyError::SensitivityParams(format!(
            "no saved bed in {} (bed.pdck, or bed_rocks.csv with its companions)",
            params.bed.display()
        )));
    }
    let mut plan: Vec<(Option<Parameter>, Real, ExperimentConfig)> = vec![(None, 0.0, params.base)];
    for v in &params.variations {
        if v.values.is_empty() {
            return Err(StudyError::SensitivityParams(format!(
                "{}: no values",
                v.parameter.key()
            )));
        }
        for &value in &v.values {
            let config = v
                .parameter
                .apply(&params.base, value)
                .map_err(StudyError::SensitivityParams)?;
            plan.push((Some(v.parameter), value, config));
        }
    }
    std::fs::create_dir_all(&params.out).map_err(|source| StudyError::Io {
        path: params.out.clone(),
        source,
    })?;
    let mut runs = Vec::with_capacity(plan.len());
    let size_mm = params.base.rock.mean_size * 1e3;
    for (k, (parameter, value, config)) in plan.iter().enumerate() {
        let label = run_label(*parameter, *value);
        let prefix = format!("[run {}/{} · {label}]", k + 1, plan.len());
        let mut stage = |stage: &str, text: String| progress(format!("{prefix} {stage}: {text}"));
        let result = run_one(
            config,
            &params.out.join(&label),
            Some(&params.bed),
            &format!("{size_mm} mm rocks, {label}"),
            &mut stage,
        )?;
        let p = &result.penetration;
        let run = SensitivityRun {
            parameter: *parameter,
            value: *value,
            run: StudyRun::from_result(size_mm, config, &result),
            steps: p.steps,
            energy_lost: p.projectile_energy_loss,
            damping: p.dissipated_damping,
            friction: p.dissipated_friction,
        };
        progress(format!(
            "{prefix} residual {:.1} m/s, deflection {:.2}° / {:.2}°, {:.1} s",
            run.run.residual_speed,
            run.run.velocity_deflection,
            run.run.axis_deflection,
            run.run.penetration_s
        ));
        runs.push(run);
        write_outputs(params, &runs)?;
    }
    Ok(runs)
}

/// Writes `sensitivity.csv` and `sensitivity.md`.
pub fn write_outputs(
    params: &SensitivityParams,
    runs: &[SensitivityRun],
) -> Result<(), StudyError> {
    let write = |name: &str, text: String| {
        let path = params.out.join(name);
        std::fs::write(&path, text).map_err(|source| StudyError::Io { path, source })
    };
    let csv = csv_text(
        SensitivityRun::CSV_HEADER,
        runs.iter().map(SensitivityRun::csv_row),
    );
    write("sensitivity.csv", csv)?;
    write("sensitivity.md", sensitivity_table(params, runs))
}

/// The table of the runs, with each run's residual velocity against the base's.
pub fn sensitivity_table(params: &SensitivityParams, runs: &[SensitivityRun]) -> String {
    let mut s = String::new();
    let b = &params.base;
    let _ = writeln!(
        s,
        "# Contact-parameter sensitivity ({}, {} mm rocks, seed {})\n",
        params.label,
        b.rock.mean_size * 1e3,
        b.rock.seed
    );
    let _ = writeln!(
        s,
        "Every run starts from the bed in `{}`; one parameter varies at a time, the others keep the \
         file's values (k_n = {:e} N/m, k_s = {:e} N/m, f = {}, e_r = {}, e_b = {}). Deflections at the \
         end of the run; energies over the penetration.\n",
        params.bed.display(),
        b.contact.normal_stiffness,
        b.contact.tangential_stiffness,
        b.contact.friction,
        b.contact.restitution_rocks,
        b.contact.restitution_projectile
    );
    let _ = writeln!(
        s,
        "| parameter | value | exited | residual (m/s) | change vs base (m/s) | velocity / axis deflection (°) | disturbed (sizes) | energy lost (J) | damping (J) | friction (J) | max overlap / size | steps | wall (s) |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let base = runs.iter().find(|r| r.parameter.is_none());
    for r in runs {
        let change = base.map_or(Real::NAN, |b| r.run.residual_speed - b.run.residual_speed);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {:+.1} | {:.2} / {:.2} | {:.2} | {:.3e} | {:.3e} | {:.3e} | {:.3} | {} | {:.1} |",
            r.parameter.map_or("base", Parameter::key),
            if r.parameter.is_some() { format!("{}", r.value) } else { "–".into() },
            if r.run.exited { "yes" } else { "no" },
            r.run.residual_speed,
            change,
            r.run.velocity_deflection,
            r.run.axis_deflection,
            r.run.disturbed_width_sizes,
            r.energy_lost,
            r.damping,
            r.friction,
            r.run.max_overlap_ratio,
            r.steps,
            r.run.penetration_s
        );
    }
    s
}

/// The folder name of the run varying `parameter` to `value` (`base` for none).
pub fn run_label(parameter: Option<Parameter>, value: Real) -> String {
    match parameter {
        None => "base".into(),
        Some(p) => format!("{}_{value}", p.key().trim_start_matches("contact.")),
    }
}
