//! Measuring another commit in the same run: its tree checked out as a git worktree under `target/perf/`,
//! its own `perf` binary built there (release profile, a target directory of its own so the current build
//! is untouched), then counted by the same runner as the current binary.
//!
//! This is what makes counts comparable across machines: when the history holds no counts of the baseline
//! commit under this machine's key (another CPU, rustc or valgrind), both commits are counted here, now.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::PerfError;

/// Builds the `perf` binary of `commit` (of the repository at `root`) in `work`; returns its path.
pub fn build_at(root: &Path, commit: &str, work: &Path) -> Result<PathBuf, PerfError> {
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
    Ok(target.join("release").join("perf"))
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
