//! What a case is: a named computation that reads its parameters and tolerances from a TOML data file and
//! produces checked rows, tables and plots through a [`CaseContext`].
//!
//! Adding a case is one module under `validation/src/cases/` implementing [`Case`], one data file
//! `validation/cases/<name>.toml`, and one line in [`crate::cases::registry`] (see `validation/README.md`).

use std::collections::BTreeMap;

use serde::de::DeserializeOwned;
use serde::Deserialize;

pub use crate::check::{format_value, Check, Comparison, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;

/// How much work a run does. `Quick` is the default of `cargo validate` and what the `cargo test` gates
/// run; `Full` runs everything at full scale.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Profile {
    Quick,
    Full,
}

impl Profile {
    /// The profile's name as used in the TOML data files (`[profile.quick]`, `[profile.full]`) and reports.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Quick => "quick",
            Profile::Full => "full",
        }
    }
}

/// A numeric value from a case data file together with where it comes from.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Quantity {
    pub value: f64,
    pub unit: String,
    /// Where the value comes from: analytical formula, issue, paper and table, reference code and version.
    pub source: String,
}

/// The content of `validation/cases/<name>.toml`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseData {
    pub title: String,
    pub description: String,
    /// Estimated run time of the full profile on the 2-core reference machine, seconds; printed before a
    /// full run when no earlier full run of the case was recorded in `reports/runs.csv`.
    #[serde(default)]
    pub full_estimate_s: Option<f64>,
    /// Parameters per profile (`[profile.quick]`, `[profile.full]`), typed by each case.
    pub profile: BTreeMap<String, toml::Table>,
    /// Pass/fail bounds, each with its source.
    #[serde(default)]
    pub tolerance: BTreeMap<String, Quantity>,
    /// Reference values, each with its source.
    #[serde(default)]
    pub reference: BTreeMap<String, Quantity>,
}

impl CaseData {
    /// Parses a case data file.
    pub fn parse(case: &str, text: &str) -> Result<Self, SuiteError> {
        toml::from_str(text).map_err(|source| SuiteError::CaseData {
            case: case.to_string(),
            source,
        })
    }

    /// The case's typed parameters for `profile`.
    pub fn params<T: DeserializeOwned>(
        &self,
        case: &str,
        profile: Profile,
    ) -> Result<T, SuiteError> {
        let table = self
            .profile
            .get(profile.name())
            .ok_or_else(|| SuiteError::CaseDataField {
                case: case.to_string(),
                msg: format!("missing table [profile.{}]", profile.name()),
            })?;
        table
            .clone()
            .try_into()
            .map_err(|source| SuiteError::CaseData {
                case: case.to_string(),
                source,
            })
    }

    /// A tolerance by key.
    pub fn tolerance(&self, case: &str, key: &str) -> Result<&Quantity, SuiteError> {
        self.tolerance
            .get(key)
            .ok_or_else(|| SuiteError::CaseDataField {
                case: case.to_string(),
                msg: format!("missing [tolerance.{key}]"),
            })
    }

    /// A reference value by key.
    pub fn reference(&self, case: &str, key: &str) -> Result<&Quantity, SuiteError> {
        self.reference
            .get(key)
            .ok_or_else(|| SuiteError::CaseDataField {
                case: case.to_string(),
                msg: format!("missing [reference.{key}]"),
            })
    }
}

/// A validation case. Implementations are unit structs listed in [`crate::cases::registry`].
pub trait Case: Send + Sync {
    /// Short name used on the command line, in file names and in `summary.csv` (`[a-z0-9_]+`).
    fn name(&self) -> &'static str;
    /// The text of `validation/cases/<name>.toml` (use `include_str!`).
    fn data(&self) -> &'static str;
    /// Whether a plain `cargo validate` (no case named) runs this case. Expensive or machine-dependent
    /// cases (performance history) return false and run only when named.
    fn in_default_run(&self) -> bool {
        true
    }
    /// Files in `reports/<name>/` that a new run must not delete (e.g. a performance history).
    fn persistent_files(&self) -> &'static [&'static str] {
        &[]
    }
    /// Runs the case: computes the figures and records checks, tables and plots through `ctx`.
    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_comparisons_and_nan() {
        assert!(Target::at_most(1.0).holds(1.0));
        assert!(!Target::at_most(1.0).holds(1.0 + 1e-15));
        assert!(Target::at_least(0.5).holds(0.7));
        assert!(!Target::at_least(0.5).holds(f64::NAN));
        assert!(!Target::at_most(0.5).holds(f64::NAN));
        assert!(Target::equal(0.0).holds(0.0));
        assert!(!Target::equal(0.0).holds(1.0));
    }

    #[test]
    fn formatting_is_deterministic() {
        assert_eq!(format_value(0.0), "0");
        assert_eq!(format_value(42.0), "42");
        assert_eq!(format_value(1e-10), "1.000000e-10");
        assert_eq!(format_value(f64::NAN), "NaN");
        assert_eq!(Target::at_most(1e-10).render(), "<= 1.000000e-10");
    }

    #[test]
    fn case_data_parses_profiles_and_sources() {
        let text = r#"
title = "T"
description = "D"
[profile.quick]
n = 3
[tolerance.depth]
value = 1e-10
unit = "1"
source = "a test fixture"
"#;
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct P {
            n: usize,
        }
        let data = CaseData::parse("t", text).unwrap();
        let p: P = data.params("t", Profile::Quick).unwrap();
        assert_eq!(p.n, 3);
        assert!(data.params::<P>("t", Profile::Full).is_err());
        assert_eq!(data.tolerance("t", "depth").unwrap().value, 1e-10);
        assert!(data.reference("t", "x").is_err());
    }
}
