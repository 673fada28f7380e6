//! The suite's typed errors: one enum for everything that can go wrong while running cases and writing the
//! report. Binaries wrap it in `anyhow` at the command-line edge.

use std::path::PathBuf;

/// An error of the validation suite (loading case data, running a case, writing the report).
#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    /// A case name on the command line (or in a gate) that the registry does not know.
    #[error("unknown case `{name}`; known cases: {known}")]
    UnknownCase { name: String, known: String },
    /// The case's TOML data file does not parse or does not match the case's schema.
    #[error("validation/cases/{case}.toml: {source}")]
    CaseData {
        case: String,
        #[source]
        source: toml::de::Error,
    },
    /// A field the case needs is missing from its TOML data file.
    #[error("validation/cases/{case}.toml: {msg}")]
    CaseDataField { case: String, msg: String },
    /// Reading or writing a file of the report.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Reading or writing a CSV file of the report.
    #[error("{path}: {source}")]
    Csv {
        path: PathBuf,
        #[source]
        source: csv::Error,
    },
    /// A file of the report or of its inputs that does not parse (the message says what is wrong).
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        message: String,
    },
    /// Rendering a plot.
    #[error("plot `{name}`: {msg}")]
    Plot { name: String, msg: String },
    /// A case could not produce its figures (the message names the inputs).
    #[error("case `{case}`: {msg}")]
    Case { case: String, msg: String },
}

impl SuiteError {
    /// The error of case `case` that could not produce its figures; `msg` names the inputs.
    pub fn case(case: &str, msg: impl Into<String>) -> SuiteError {
        SuiteError::Case {
            case: case.to_string(),
            msg: msg.into(),
        }
    }

    /// Wraps an I/O error with the path it concerns.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> SuiteError {
        let path = path.into();
        move |source| SuiteError::Io { path, source }
    }

    /// Wraps a CSV error with the path it concerns.
    pub fn csv(path: impl Into<PathBuf>) -> impl FnOnce(csv::Error) -> SuiteError {
        let path = path.into();
        move |source| SuiteError::Csv { path, source }
    }
}
