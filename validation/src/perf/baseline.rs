//! Measuring another commit in the same run: its tree checked out as a git worktree under `target/perf/`,
//! its own `perf` binary built there (release profile, a target directory of its own so the current build
//! is untouched), then counted by the same runner as the current binary.
//!
//! This is what makes counts comparable across machines: when the history holds no counts of the baseline
//! commit under this machine's key (another CPU, rustc or valgrind), both commits are counted here, now.
//! The baseline counts itself (its own `perf count`, whose output is the one contract between versions),
//! so a later change of how benchmarks are run does not break the comparison with an earlier commit.

use std::path::Path;
use std::process::Command;

use super::{FigureCounts, PerfError};

/// Builds the `perf` binary of `commit` (of the repository at `root`) in `work` and counts its figures
/// with it (`perf count`, only `benches` when not empty).
pub fn count_at(
    root: &Path,
    commit: &str,
    work: &Path,
    benches: &[String],
) -> Result<FigureCounts, PerfError> {
    let tree = work.join("baseline-tree").join(commit);
    let target = work.join("baseline-target");
    git(root, &["worktree", "prune"])?;
    if !tree.join("Cargo.toml").exists() {
        let tree_arg = tree.display().to_string();
        git(
            root,
            &["worktree", "add", "--force", "--detach", &tree_arg, commit],
        )?;
    }
    eprintln!(
        "perf: building the perf binary of {commit} in {} (release)",
        tree.display()
    );
    let status = Command::new(env!("CARGO"))
        .args([
            "build",
            "--release",
            "--quiet",
            "-p",
            "polydem-validation",
            "--bin",
            "perf",
        ])
        .current_dir(&tree)
        .env("CARGO_TARGET_DIR", &target)
        .status()
        .map_err(|e| PerfError::Build(format!("cargo could not be started: {e}")))?;
    if !status.success() {
        return Err(PerfError::Build(format!(
            "building the perf binary of {commit} failed ({status}); a commit from before the benchmark set has none"
        )));
    }
    let binary = target.join("release").join("perf");
    let mut command = Command::new(&binary);
    command.arg("count").env("CARGO_TARGET_DIR", &target);
    for bench in benches {
        command.args(["--bench", bench]);
    }
    let out = command
        .output()
        .map_err(|e| PerfError::Build(format!("{}: {e}", binary.display())))?;
    if !out.status.success() {
        return Err(PerfError::Build(format!(
            "counting {commit} with its own perf binary failed ({}):\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        )));
    }
    parse_count_table(&String::from_utf8_lossy(&out.stdout))
        .map_err(|e| PerfError::Build(format!("{commit}: perf count: {e}")))
}

/// Reads the table `perf count` prints: a header line, then `figure instructions work` per line.
pub fn parse_count_table(text: &str) -> Result<FigureCounts, String> {
    let mut counts = FigureCounts::new();
    for line in text.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let parsed = match fields[..] {
            [figure, n, work] => n.parse().ok().zip(work.parse().ok()).map(|nw| (figure, nw)),
            _ => None,
        };
        let (figure, nw) = parsed.ok_or_else(|| format!("malformed line `{line}`"))?;
        counts.insert(figure.to_string(), nw);
    }
    if counts.is_empty() {
        return Err("no figures".to_string());
    }
    Ok(counts)
}

/// Runs git in `root`; its output, or an error with git's message.
pub fn git(root: &Path, args: &[&str]) -> Result<String, PerfError> {
    let out = Command::new("git")
        .args(args)
        .current_dir(root)
        .output()
        .map_err(|e| PerfError::Git(format!("git {}: {e}", args.join(" "))))?;
    if !out.status.success() {
        return Err(PerfError::Git(format!(
            "git {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_count_table_parses_and_a_malformed_line_is_refused() {
        let text = "figure      instructions   work\nstep/a   123   4\ncontact/b 56 0\n";
        let counts = parse_count_table(text).unwrap();
        assert_eq!(counts["step/a"], (123, 4));
        assert_eq!(counts["contact/b"], (56, 0));
        assert!(parse_count_table("header\nstep/a 12x 4\n").is_err());
        assert!(parse_count_table("header\n").is_err());
    }
}
