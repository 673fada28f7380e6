//! `reports/perf/history.csv`: one row per figure per recorded run, recorded only from a clean tree.
//!
//! Columns: `commit` (12 hex digits, the commit measured), `date` (UTC), the [`MachineKey`] columns
//! (`machine`, `cpu_flags`, `rustc`, `valgrind`, `glibc`, `threads`), `figure`, `value`, `unit` (`Ir` for
//! instruction counts, `ns` for wall times), `work` (the benchmark's own measure of what it did), and for
//! wall-time figures measured against a peer in the same run: `peer`, `peer_value`, `ratio` (ours / peer),
//! `load_avg` (1-minute load average before and after) and `cpu_s` (CPU seconds of the measurement).

use std::path::Path;

use super::key::MachineKey;
use crate::error::SuiteError;

/// The header of `history.csv`.
pub const HEADER: [&str; 17] = [
    "commit",
    "date",
    "machine",
    "cpu_flags",
    "rustc",
    "valgrind",
    "glibc",
    "threads",
    "figure",
    "value",
    "unit",
    "work",
    "peer",
    "peer_value",
    "ratio",
    "load_avg",
    "cpu_s",
];

/// The unit of instruction counts.
pub const INSTRUCTIONS: &str = "Ir";

/// One row of the history.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub commit: String,
    pub date: String,
    pub key: MachineKey,
    pub figure: String,
    pub value: f64,
    pub unit: String,
    pub work: String,
    pub peer: String,
    pub peer_value: String,
    pub ratio: String,
    pub load_avg: String,
    pub cpu_s: String,
}

impl Row {
    /// An instruction-count row.
    pub fn count(
        commit: &str,
        date: &str,
        key: &MachineKey,
        figure: &str,
        instructions: u64,
        work: u64,
    ) -> Self {
        Self {
            commit: commit.to_string(),
            date: date.to_string(),
            key: key.clone(),
            figure: figure.to_string(),
            value: instructions as f64,
            unit: INSTRUCTIONS.to_string(),
            work: work.to_string(),
            peer: String::new(),
            peer_value: String::new(),
            ratio: String::new(),
            load_avg: String::new(),
            cpu_s: String::new(),
        }
    }

    pub fn is_count(&self) -> bool {
        self.unit == INSTRUCTIONS
    }

    fn to_record(&self) -> Vec<String> {
        let k = &self.key;
        let value = if self.is_count() {
            format!("{:.0}", self.value)
        } else {
            format!("{:.1}", self.value)
        };
        vec![
            self.commit.clone(),
            self.date.clone(),
            k.machine.clone(),
            k.cpu_flags.clone(),
            k.rustc.clone(),
            k.valgrind.clone(),
            k.glibc.clone(),
            k.threads.to_string(),
            self.figure.clone(),
            value,
            self.unit.clone(),
            self.work.clone(),
            self.peer.clone(),
            self.peer_value.clone(),
            self.ratio.clone(),
            self.load_avg.clone(),
            self.cpu_s.clone(),
        ]
    }

    fn from_record(rec: &csv::StringRecord, line: u64, path: &Path) -> Result<Self, SuiteError> {
        let bad = |what: String| SuiteError::Parse {
            path: path.to_owned(),
            line: line as usize,
            message: what,
        };
        if rec.len() != HEADER.len() {
            return Err(bad(format!(
                "{} fields, expected {}",
                rec.len(),
                HEADER.len()
            )));
        }
        let f = |i: usize| rec[i].to_string();
        let value = rec[9]
            .parse::<f64>()
            .map_err(|e| bad(format!("value `{}`: {e}", &rec[9])))?;
        let threads = rec[7]
            .parse::<usize>()
            .map_err(|e| bad(format!("threads `{}`: {e}", &rec[7])))?;
        Ok(Self {
            commit: f(0),
            date: f(1),
            key: MachineKey {
                machine: f(2),
                cpu_flags: f(3),
                rustc: f(4),
                valgrind: f(5),
                glibc: f(6),
                threads,
            },
            figure: f(8),
            value,
            unit: f(10),
            work: f(11),
            peer: f(12),
            peer_value: f(13),
            ratio: f(14),
            load_avg: f(15),
            cpu_s: f(16),
        })
    }
}

/// Reads the history (empty when the file does not exist). A row of the wrong shape is an error naming
/// the file and line.
pub fn read(path: &Path) -> Result<Vec<Row>, SuiteError> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let mut reader = csv::Reader::from_path(path).map_err(SuiteError::csv(path))?;
    let header: Vec<String> = reader
        .headers()
        .map_err(SuiteError::csv(path))?
        .iter()
        .map(str::to_string)
        .collect();
    if header != HEADER {
        return Err(SuiteError::Parse {
            path: path.to_owned(),
            line: 1,
            message: format!(
                "header `{}`, expected `{}`",
                header.join(","),
                HEADER.join(",")
            ),
        });
    }
    let mut rows = Vec::new();
    for rec in reader.records() {
        let rec = rec.map_err(SuiteError::csv(path))?;
        let line = rec.position().map_or(0, |p| p.line());
        rows.push(Row::from_record(&rec, line, path)?);
    }
    Ok(rows)
}

/// Appends `rows` to the history at `path` (written whole to a temporary file, then renamed).
pub fn append(path: &Path, rows: &[Row]) -> Result<(), SuiteError> {
    let mut all = read(path)?;
    all.extend_from_slice(rows);
    let tmp = path.with_extension("csv.tmp");
    {
        let mut w = csv::Writer::from_path(&tmp).map_err(SuiteError::csv(&tmp))?;
        w.write_record(HEADER).map_err(SuiteError::csv(&tmp))?;
        for r in &all {
            w.write_record(r.to_record())
                .map_err(SuiteError::csv(&tmp))?;
        }
        w.flush().map_err(SuiteError::io(&tmp))?;
    }
    std::fs::rename(&tmp, path).map_err(SuiteError::io(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_round_trip_through_the_file_and_a_wrong_header_is_refused() {
        let dir = std::env::temp_dir().join(format!("polydem_perf_history_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("history.csv");
        let key = MachineKey {
            machine: "2 cores, CPU".into(),
            cpu_flags: "avx avx2".into(),
            rustc: "rustc 1.95.0".into(),
            valgrind: "valgrind-3.19.0".into(),
            glibc: "2.36".into(),
            threads: 1,
        };
        let row = Row::count(
            "0123456789ab",
            "2026-01-01T00:00:00Z",
            &key,
            "step/x",
            123456789,
            42,
        );
        append(&path, std::slice::from_ref(&row)).unwrap();
        append(&path, std::slice::from_ref(&row)).unwrap();
        assert_eq!(read(&path).unwrap(), vec![row.clone(), row]);
        std::fs::write(&path, "commit,date\n").unwrap();
        let err = read(&path).unwrap_err().to_string();
        assert!(
            err.contains("history.csv") && err.contains("header"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
