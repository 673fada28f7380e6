//! The regression gate: a figure whose instruction count grows by more than the threshold against the
//! recorded baseline fails, unless the growth is accepted in `reports/perf/accepted.toml`.
//!
//! The baseline of a commit is the newest commit among its ancestors (itself included) that has counts in
//! the history. Counts are compared only under the same [`MachineKey`]; when the history has none for this
//! machine's key, the baseline commit is measured again in the same run ([`super::baseline`]).
//!
//! An acceptance names the figure, the baseline commit it is measured against, the largest ratio accepted
//! and the reason. It applies to that baseline only: once a later commit is recorded, its counts are the
//! new baseline and the acceptance has done its job (it stays in the file as the record of why the figure
//! grew).

use super::FigureCounts;
use std::path::Path;

use serde::Deserialize;

use super::history::Row;
use super::key::MachineKey;
use crate::error::SuiteError;

/// Growth of an instruction count that fails the gate: 2 %. Counts repeat exactly, so any growth is
/// real; 2 % leaves room for the small shifts of code layout that an unrelated change can cause.
pub const DEFAULT_THRESHOLD: f64 = 0.02;

/// One accepted regression.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Acceptance {
    pub figure: String,
    /// The baseline commit (a prefix of at least 7 hex digits) the growth is measured against.
    pub baseline: String,
    /// The largest count / baseline accepted.
    pub max_ratio: f64,
    pub reason: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AcceptedFile {
    #[serde(default)]
    accept: Vec<Acceptance>,
}

/// Reads `accepted.toml` (no file: nothing accepted). Errors name the file, line and field.
pub fn read_accepted(path: &Path) -> Result<Vec<Acceptance>, SuiteError> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(SuiteError::io(path)(e)),
    };
    let parse_error = |line: usize, message: String| SuiteError::Parse {
        path: path.to_owned(),
        line,
        message,
    };
    let file: AcceptedFile = toml::from_str(&text).map_err(|e| {
        let line = e
            .span()
            .map_or(0, |s| text[..s.start].lines().count().max(1));
        parse_error(line, e.message().to_string())
    })?;
    for a in &file.accept {
        let line = text
            .find(&a.figure)
            .map_or(0, |at| text[..at].lines().count());
        if a.baseline.len() < 7 || !a.baseline.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(parse_error(
                line,
                format!(
                    "baseline `{}`: not a commit prefix of 7 or more hex digits",
                    a.baseline
                ),
            ));
        }
        if !(a.max_ratio.is_finite() && a.max_ratio > 1.0) {
            return Err(parse_error(
                line,
                format!("max_ratio {}: must be a finite number above 1", a.max_ratio),
            ));
        }
        if a.reason.trim().is_empty() {
            return Err(parse_error(
                line,
                format!("figure `{}`: the reason is empty", a.figure),
            ));
        }
    }
    Ok(file.accept)
}

/// How one figure fared.
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    /// Within the threshold (or fewer instructions).
    Pass,
    /// Grew past the threshold, within an acceptance (its reason).
    Accepted(String),
    /// Grew past the threshold, not accepted.
    Regressed,
    /// No baseline figure of that name (a new benchmark).
    New,
    /// In the baseline, not measured now (a benchmark removed or renamed).
    Missing,
}

/// The verdict on one figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    pub figure: String,
    pub baseline: Option<(u64, u64)>,
    pub now: Option<(u64, u64)>,
    pub status: Status,
}

impl Verdict {
    /// Count now / count of the baseline.
    pub fn ratio(&self) -> Option<f64> {
        match (self.baseline, self.now) {
            (Some((b, _)), Some((n, _))) if b > 0 => Some(n as f64 / b as f64),
            _ => None,
        }
    }
}

/// Compares counts `now` (figure → (instructions, work)) with `baseline` measured at commit
/// `baseline_commit`.
pub fn compare(
    now: &FigureCounts,
    baseline: &FigureCounts,
    baseline_commit: &str,
    threshold: f64,
    accepted: &[Acceptance],
) -> Vec<Verdict> {
    let mut names: Vec<&String> = now.keys().chain(baseline.keys()).collect();
    names.sort();
    names.dedup();
    names
        .into_iter()
        .map(|figure| {
            let (b, n) = (baseline.get(figure).copied(), now.get(figure).copied());
            let status = match (b, n) {
                (None, _) => Status::New,
                (_, None) => Status::Missing,
                (Some((b, _)), Some((n, _))) => {
                    let ratio = n as f64 / (b.max(1)) as f64;
                    if ratio <= 1.0 + threshold {
                        Status::Pass
                    } else {
                        match accepted.iter().find(|a| {
                            &a.figure == figure
                                && (baseline_commit.starts_with(&a.baseline)
                                    || a.baseline.starts_with(baseline_commit))
                                && ratio <= a.max_ratio
                        }) {
                            Some(a) => Status::Accepted(a.reason.clone()),
                            None => Status::Regressed,
                        }
                    }
                }
            };
            Verdict {
                figure: figure.clone(),
                baseline: b,
                now: n,
                status,
            }
        })
        .collect()
}

/// The counts of `commit` under `key` in the history (figure → (instructions, work)); the newest row of
/// a figure wins when a commit was recorded twice.
pub fn counts_of(history: &[Row], commit: &str, key: &MachineKey) -> FigureCounts {
    history
        .iter()
        .filter(|r| r.is_count() && r.commit == commit && &r.key == key)
        .map(|r| {
            (
                r.figure.clone(),
                (r.value as u64, r.work.parse().unwrap_or(0)),
            )
        })
        .collect()
}

/// The commits of the history that have counts, newest first along `ancestry` (the output of
/// `git rev-list HEAD`, full hashes, newest first).
pub fn recorded_ancestors(history: &[Row], ancestry: &[String]) -> Vec<String> {
    ancestry
        .iter()
        .filter_map(|full| {
            history
                .iter()
                .find(|r| r.is_count() && full.starts_with(&r.commit))
                .map(|r| r.commit.clone())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(items: &[(&str, u64)]) -> FigureCounts {
        items
            .iter()
            .map(|(f, n)| (f.to_string(), (*n, 1)))
            .collect()
    }

    #[test]
    fn growth_past_the_threshold_fails_unless_accepted_against_that_baseline() {
        let base = counts(&[("a", 1000), ("b", 1000), ("c", 1000), ("gone", 5)]);
        let now = counts(&[("a", 1020), ("b", 1021), ("c", 900), ("new", 7)]);
        let v = compare(&now, &base, "0123456789ab", 0.02, &[]);
        let status = |f: &str| v.iter().find(|x| x.figure == f).unwrap().status.clone();
        assert_eq!(
            status("a"),
            Status::Pass,
            "+2.0 % is within a 2 % threshold"
        );
        assert_eq!(status("b"), Status::Regressed, "+2.1 % is past it");
        assert_eq!(status("c"), Status::Pass);
        assert_eq!(status("new"), Status::New);
        assert_eq!(status("gone"), Status::Missing);
        let accept = |baseline: &str, max_ratio: f64| Acceptance {
            figure: "b".into(),
            baseline: baseline.into(),
            max_ratio,
            reason: "exact overlap costs more".into(),
        };
        let v = compare(
            &now,
            &base,
            "0123456789ab",
            0.02,
            &[accept("0123456", 1.05)],
        );
        assert_eq!(
            v[1].status,
            Status::Accepted("exact overlap costs more".into())
        );
        let v = compare(
            &now,
            &base,
            "0123456789ab",
            0.02,
            &[accept("fedcba9", 1.05)],
        );
        assert_eq!(
            v[1].status,
            Status::Regressed,
            "an acceptance of another baseline does not apply"
        );
        let v = compare(
            &now,
            &base,
            "0123456789ab",
            0.02,
            &[accept("0123456", 1.01)],
        );
        assert_eq!(
            v[1].status,
            Status::Regressed,
            "growth beyond the accepted ratio still fails"
        );
    }

    #[test]
    fn accepted_file_errors_name_the_line_and_field() {
        let dir =
            std::env::temp_dir().join(format!("polydem_perf_accepted_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("accepted.toml");
        std::fs::write(&path, "[[accept]]\nfigure = \"a\"\nbaseline = \"0123456\"\nmax_ratio = 1.1\nreason = \"why\"\n").unwrap();
        assert_eq!(read_accepted(&path).unwrap().len(), 1);
        std::fs::write(&path, "[[accept]]\nfigure = \"a\"\nbaseline = \"0123456\"\nmax_ratio = 1.1\nreson = \"why\"\n").unwrap();
        let err = read_accepted(&path).unwrap_err().to_string();
        assert!(
            err.contains("accepted.toml:") && err.contains("reson"),
            "{err}"
        );
        std::fs::write(
            &path,
            "[[accept]]\nfigure = \"a\"\nbaseline = \"xyz\"\nmax_ratio = 1.1\nreason = \"why\"\n",
        )
        .unwrap();
        let err = read_accepted(&path).unwrap_err().to_string();
        assert!(err.contains("baseline `xyz`"), "{err}");
        assert!(read_accepted(&dir.join("none.toml")).unwrap().is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
