//! Running cases: select from the registry, run each with its data and a progress display, time it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::case::{Case, CaseData, Check, Profile};
use crate::cases::registry;
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::progress::{Progress, ProgressMode};

/// The outcome of one case run.
#[derive(Clone, Debug)]
pub struct CaseReport {
    pub case: String,
    pub title: String,
    pub description: String,
    pub profile: Profile,
    pub checks: Vec<Check>,
    /// The markdown body of the case page (after the generated header and checks table).
    pub page: String,
    /// Wall time of the run, seconds (kept out of `summary.csv`).
    pub wall_s: f64,
    /// A case that could not complete records its error here and counts as failed.
    pub error: Option<String>,
}

impl CaseReport {
    pub fn passed(&self) -> usize {
        self.checks.iter().filter(|c| c.pass).count()
    }
    /// True when the case completed and every check passed.
    pub fn ok(&self) -> bool {
        self.error.is_none() && self.checks.iter().all(|c| c.pass)
    }
}

/// Finds a case by name.
pub fn find_case(name: &str) -> Result<&'static dyn Case, SuiteError> {
    registry()
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or_else(|| SuiteError::UnknownCase {
            name: name.to_string(),
            known: registry()
                .iter()
                .map(|c| c.name())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// The cases a run selects: the named ones (in registry order), or every case of the default run.
pub fn select(names: &[String]) -> Result<Vec<&'static dyn Case>, SuiteError> {
    if names.is_empty() {
        return Ok(registry()
            .into_iter()
            .filter(|c| c.in_default_run())
            .collect());
    }
    for n in names {
        find_case(n)?;
    }
    Ok(registry()
        .into_iter()
        .filter(|c| names.iter().any(|n| n == c.name()))
        .collect())
}

/// Runs one case. With `out`, its tables and plots go to `out/<case>/` (files of an earlier run of the
/// case are removed first, except those the case keeps, e.g. a performance history).
pub fn run_case(
    case: &dyn Case,
    profile: Profile,
    out: Option<&Path>,
    progress: ProgressMode,
) -> Result<CaseReport, SuiteError> {
    let data = CaseData::parse(case.name(), case.data())?;
    if let Some(root) = out {
        clear_case_dir(&root.join(case.name()), case.persistent_files())?;
    }
    let mut ctx = CaseContext::new(
        case.name(),
        out.map(PathBuf::from),
        Progress::new(case.name(), progress),
    );
    let start = Instant::now();
    let result = case.run(&data, profile, &mut ctx);
    let wall_s = start.elapsed().as_secs_f64();
    let (checks, page, mut progress) = ctx.finish();
    let passed = checks.iter().filter(|c| c.pass).count();
    let error = result.err().map(|e| e.to_string());
    progress.finish(&match &error {
        None => format!("{passed}/{} checks passed in {wall_s:.1} s", checks.len()),
        Some(e) => format!("ERROR after {wall_s:.1} s: {e}"),
    });
    Ok(CaseReport {
        case: case.name().to_string(),
        title: data.title,
        description: data.description,
        profile,
        checks,
        page,
        wall_s,
        error,
    })
}

/// Runs a case by name in memory (no files), without progress display: the entry point of the gates.
pub fn run_case_in_memory(name: &str, profile: Profile) -> Result<CaseReport, SuiteError> {
    run_case(find_case(name)?, profile, None, ProgressMode::Hidden)
}

fn clear_case_dir(dir: &Path, keep: &[&str]) -> Result<(), SuiteError> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(_) => return Ok(()),
    };
    for entry in entries {
        let entry = entry.map_err(SuiteError::io(dir))?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().to_string();
        if path.is_file() && !keep.contains(&name.as_str()) {
            std::fs::remove_file(&path).map_err(SuiteError::io(&path))?;
        }
    }
    Ok(())
}
