//! Performance regression tracking per commit: `cargo perf`.
//!
//! - [`benches`]: the fixed benchmark set (contact queries, steps, the rockfill penetration, scene loading,
//!   VTK and checkpoint I/O), driven through scene files and public entry points.
//! - [`callgrind`]: instruction counts of each figure under valgrind, exact from run to run.
//! - [`key`]: what a count depends on besides the code (toolchain, valgrind, glibc, CPU flags, threads).
//! - [`history`]: `reports/perf/history.csv`, one row per figure per recorded commit.
//! - [`gate`]: the comparison against the baseline and the accepted regressions.
//! - [`baseline`]: counting another commit in the same run when the history has no comparable counts.
//! - [`peers`]: wall-time ratios against a peer measured in the same run, with load and CPU time.
//! - [`page`]: the dashboard `reports/perf.md` and its plots.
//!
//! How to run, read and extend it: `docs/perf.md`.

pub mod baseline;
pub mod benches;
pub mod callgrind;
pub mod gate;
pub mod history;
pub mod key;
pub mod page;
pub mod peers;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

pub use callgrind::Count;

/// Why a perf command failed (as opposed to a figure that regressed).
#[derive(Debug, thiserror::Error)]
pub enum PerfError {
    #[error(transparent)]
    Count(#[from] callgrind::CountError),
    #[error(transparent)]
    Suite(#[from] crate::error::SuiteError),
    #[error("{0}")]
    Git(String),
    #[error("{0}")]
    Build(String),
    #[error("preparing the benchmarks' inputs: {0}")]
    Prepare(String),
}

/// Options of one counting run.
#[derive(Clone, Debug, Default)]
pub struct CountOptions {
    /// Benchmarks to run (empty: the binary's whole set).
    pub benches: Vec<String>,
    /// Disable a skip of the step in the step benchmarks: a planted regression, to show that the gate
    /// catches one.
    pub plant_regression: bool,
}

/// Counts the figures of the `perf` binary `binary` built from the repository at `root`: prepares its
/// inputs natively, then runs each benchmark under callgrind, as many at a time as there are cores.
/// Figures come back in the order of the benchmark set. `work` names the run in error messages.
pub fn count_all(
    binary: &Path,
    root: &Path,
    work: &Path,
    options: &CountOptions,
) -> Result<Vec<Count>, PerfError> {
    let run_dir = run_dir(work)?;
    let prepared = run_dir.join(callgrind::PREPARED);
    let status = Command::new(binary)
        .arg("prepare")
        .arg("--prepared")
        .arg(&prepared)
        .arg("--root")
        .arg(root)
        .status()
        .map_err(|e| PerfError::Prepare(format!("{}: {e}", binary.display())))?;
    if !status.success() {
        return Err(PerfError::Prepare(format!(
            "{} prepare: {status}",
            binary.display()
        )));
    }
    let copy = run_dir.join(callgrind::PROGRAM);
    std::fs::copy(binary, &copy).map_err(|e| {
        PerfError::Prepare(format!("{} -> {}: {e}", binary.display(), copy.display()))
    })?;
    let link = run_dir.join(callgrind::ROOT);
    std::os::unix::fs::symlink(root, &link).map_err(|e| {
        PerfError::Prepare(format!("{} -> {}: {e}", link.display(), root.display()))
    })?;
    let names = if options.benches.is_empty() {
        bench_names(binary)?
    } else {
        options.benches.clone()
    };
    let mut extra = Vec::new();
    if options.plant_regression {
        extra.push("--plant-regression".to_string());
    }
    let program = callgrind::Program {
        run_dir: &run_dir,
        extra_args: &extra,
    };
    let lanes = std::thread::available_parallelism().map_or(1, |n| n.get());
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<_> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..lanes.min(names.len()))
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(name) = names.get(i) else { break };
                        let scratch = work.join("callgrind").join(name);
                        eprintln!("perf: counting {name} ({})", binary.display());
                        done.push((i, callgrind::count(&program, name, &scratch)));
                    }
                    done
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("counting thread"))
            .collect()
    });
    let mut ordered: Vec<_> = results;
    ordered.sort_by_key(|(i, _)| *i);
    let mut counts = Vec::new();
    for (_, result) in ordered {
        counts.extend(result?);
    }
    std::fs::remove_dir_all(&run_dir)
        .map_err(|e| PerfError::Prepare(format!("{}: {e}", run_dir.display())))?;
    Ok(counts)
}

/// A fresh run directory whose path has the same length on every machine and for every commit counted
/// (`/tmp/polydem-perf-` and the process id in ten digits): the counted process starts in it, and the
/// length of its working directory and executable path shifts its initial stack, which moved some counts
/// by up to ~100 instructions. `work` is where the directory's creation is reported on error only.
fn run_dir(work: &Path) -> Result<PathBuf, PerfError> {
    let dir = PathBuf::from(format!("/tmp/polydem-perf-{:010}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| {
        PerfError::Prepare(format!("{} (for {}): {e}", dir.display(), work.display()))
    })?;
    Ok(dir)
}

/// The benchmark names of a `perf` binary (`perf list --names`).
fn bench_names(binary: &Path) -> Result<Vec<String>, PerfError> {
    let out = Command::new(binary)
        .args(["list", "--names"])
        .output()
        .map_err(|e| PerfError::Prepare(format!("{}: {e}", binary.display())))?;
    if !out.status.success() {
        return Err(PerfError::Prepare(format!(
            "{} list --names: {}",
            binary.display(),
            out.status
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .map(str::to_string)
        .collect())
}

/// Counts as the gate compares them: figure → (instructions, work).
pub type FigureCounts = BTreeMap<String, (u64, u64)>;

/// The counts of a run keyed by figure.
pub fn by_figure(counts: &[Count]) -> FigureCounts {
    counts
        .iter()
        .map(|c| (c.figure.clone(), (c.instructions, c.work)))
        .collect()
}

/// The `target/perf` directory of this workspace (worktrees, prepared inputs, callgrind dumps).
pub fn work_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("perf")
}
