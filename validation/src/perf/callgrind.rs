//! Counting instructions with valgrind's callgrind: each benchmark runs in its own process under
//! `valgrind --tool=callgrind`, collecting only inside [`super::benches::measured_region`] and dumping after
//! each call of it, so dump *k* holds exactly the instructions of the benchmark's *k*-th figure.
//!
//! Instruction counts (`Ir`) repeat exactly for the same binary, input and environment whatever else the
//! machine is doing, which wall times on a shared 2-core machine do not. They depend on the binary (rustc,
//! profile), on valgrind, and on the CPU features valgrind shows the program (glibc picks its `memcpy` and
//! friends by them): [`super::key::MachineKey`] records all of these beside every figure. Everything runs on
//! one thread (`RAYON_NUM_THREADS=1`): callgrind serialises threads, and a thread pool's spinning and
//! work stealing would make counts depend on timing.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The function whose calls are the measured regions, by its demangled name (exactly: callgrind 3.19 does
/// not dump after a function matched by a pattern ending in `*`).
pub const REGION: &str = "polydem_validation::perf::benches::measured_region";

/// One counted figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Count {
    pub figure: String,
    /// Instructions executed in the measured region.
    pub instructions: u64,
    /// The benchmark's own measure of the work done (contacts, bodies, bytes).
    pub work: u64,
}

/// Why counting failed.
#[derive(Debug, thiserror::Error)]
pub enum CountError {
    #[error("valgrind could not be started ({0}); install it (Debian: apt-get install valgrind)")]
    NoValgrind(std::io::Error),
    #[error("benchmark `{bench}` failed under valgrind (exit {status}):\n{stderr}")]
    Failed {
        bench: String,
        status: String,
        stderr: String,
    },
    #[error("benchmark `{bench}`: {message}")]
    Output { bench: String, message: String },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// The program a count runs, as the counted process sees it: `./perf` (a copy of the binary) in `run_dir`,
/// started as `./perf exec BENCH --prepared prepared --root root [extra_args]` with a fixed environment. Everything on
/// the process's initial stack is then the same whichever checkout, target directory or shell it comes
/// from: the environment's size alone moved some counts by up to ~50 instructions.
pub struct Program<'a> {
    pub run_dir: &'a Path,
    pub extra_args: &'a [String],
}

/// The names, inside the run directory, of the copy of the binary, of the prepared inputs' directory and of
/// the link to the repository the inputs come from (so that every path the benchmarks open has the same
/// length whatever the checkout's location: a longer path moved a scene load's count by 0.8 %, through
/// the heap's layout).
pub const PROGRAM: &str = "perf";
pub const PREPARED: &str = "prepared";
pub const ROOT: &str = "root";

/// Counts the figures of benchmark `bench` under callgrind. Dump files go to `scratch` (created; removed on
/// success).
pub fn count(program: &Program, bench: &str, scratch: &Path) -> Result<Vec<Count>, CountError> {
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| CountError::Io { path, source }
    };
    std::fs::create_dir_all(scratch).map_err(io(scratch))?;
    let out_file = scratch.join(format!("callgrind.{bench}"));
    let valgrind = find_valgrind().ok_or_else(|| {
        CountError::NoValgrind(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "not on PATH",
        ))
    })?;
    let output = Command::new(valgrind)
        .arg("--tool=callgrind")
        .arg("--collect-atstart=no")
        .arg(format!("--toggle-collect={REGION}"))
        .arg(format!("--dump-after={REGION}"))
        .arg(format!("--callgrind-out-file={}", out_file.display()))
        .arg(format!("./{PROGRAM}"))
        .args(["exec", bench, "--prepared", PREPARED, "--root", ROOT])
        .args(program.extra_args)
        .current_dir(program.run_dir)
        .env_clear()
        .env("PATH", "/usr/bin:/bin")
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .map_err(CountError::NoValgrind)?;
    let fail = |message: String| CountError::Output {
        bench: bench.to_string(),
        message,
    };
    if !output.status.success() {
        return Err(CountError::Failed {
            bench: bench.to_string(),
            status: output.status.to_string(),
            stderr: tail(&String::from_utf8_lossy(&output.stderr), 30),
        });
    }
    let figures = parse_figures(&String::from_utf8_lossy(&output.stdout)).map_err(fail)?;
    let mut counts = Vec::with_capacity(figures.len());
    for (k, (figure, work)) in figures.into_iter().enumerate() {
        let dump = PathBuf::from(format!("{}.{}", out_file.display(), k + 1));
        let text = std::fs::read_to_string(&dump).map_err(io(&dump))?;
        let instructions =
            totals(&text).ok_or_else(|| fail(format!("{}: no `totals:` line", dump.display())))?;
        counts.push(Count {
            figure,
            instructions,
            work,
        });
    }
    let extra = PathBuf::from(format!("{}.{}", out_file.display(), counts.len() + 1));
    if extra.exists() {
        return Err(fail(format!(
            "callgrind wrote more dumps than the {} figures the benchmark reported ({} exists)",
            counts.len(),
            extra.display()
        )));
    }
    std::fs::remove_dir_all(scratch).map_err(io(scratch))?;
    Ok(counts)
}

/// The `figure NAME WORK` lines the `exec` subcommand prints, in order.
fn parse_figures(stdout: &str) -> Result<Vec<(String, u64)>, String> {
    let mut figures = Vec::new();
    for line in stdout.lines().filter(|l| l.starts_with("figure ")) {
        let mut parts = line.split_whitespace().skip(1);
        match (
            parts.next(),
            parts.next().map(str::parse::<u64>),
            parts.next(),
        ) {
            (Some(name), Some(Ok(work)), None) => figures.push((name.to_string(), work)),
            _ => return Err(format!("malformed line `{line}`")),
        }
    }
    if figures.is_empty() {
        return Err(format!(
            "reported no figure; its output was:\n{}",
            tail(stdout, 20)
        ));
    }
    Ok(figures)
}

/// The `totals:` line of a callgrind dump (events: `Ir` only, the default).
fn totals(dump: &str) -> Option<u64> {
    dump.lines()
        .find_map(|l| l.strip_prefix("totals:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
}

fn tail(text: &str, lines: usize) -> String {
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}

/// valgrind's path on this process's `PATH`.
fn find_valgrind() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join("valgrind"))
        .find(|p| p.is_file())
}

/// valgrind's version (`valgrind-3.19.0`), or `None` when it is not installed.
pub fn valgrind_version() -> Option<String> {
    let out = Command::new(find_valgrind()?)
        .arg("--version")
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_and_totals_parse_and_malformed_lines_are_refused() {
        let out = "figure contact_overlap_cold/tet 20\nnoise\nfigure step/polyhedra_box 81\n";
        assert_eq!(
            parse_figures(out).unwrap(),
            vec![
                ("contact_overlap_cold/tet".to_string(), 20),
                ("step/polyhedra_box".to_string(), 81)
            ]
        );
        assert!(parse_figures("figure a b\n").is_err());
        assert!(parse_figures("nothing\n").is_err());
        assert_eq!(
            totals("events: Ir\nsummary: 12\ntotals: 475021\n"),
            Some(475021)
        );
        assert_eq!(totals("events: Ir\n"), None);
    }
}
