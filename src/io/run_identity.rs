//! Which run an output directory belongs to: a fresh run draws an identity, records it in
//! `DIR/.polydem-run` and writes it into every checkpoint; a restart into a directory is accepted only
//! when the directory's identity is the checkpoint's, so the series of two different runs are never
//! spliced together (comparing CSV headers cannot tell two runs of the same kind apart).

use std::io::{self, Write};
use std::path::Path;

/// The name of the identity file in an output directory.
pub const RUN_FILE: &str = ".polydem-run";

/// A new identity: the clock's nanoseconds and the process id, mixed (splitmix64) so that close values
/// give unrelated identities.
pub fn new_run() -> u64 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64);
    let mut z = nanos ^ (u64::from(std::process::id()) << 32);
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The identity recorded in `dir`, if any.
pub fn recorded(dir: &Path) -> io::Result<Option<u64>> {
    let path = dir.join(RUN_FILE);
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => {
            return Err(io::Error::new(
                e.kind(),
                format!("cannot read {}: {e}", path.display()),
            ))
        }
    };
    u64::from_str_radix(text.trim(), 16).map(Some).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "{}:1: \"{}\" is not a run identity (16 hex digits)",
                path.display(),
                text.trim()
            ),
        )
    })
}

/// Records `run` as the identity of `dir` (written aside, synced and renamed).
pub fn record(dir: &Path, run: u64) -> io::Result<()> {
    let path = dir.join(RUN_FILE);
    let partial = dir.join(format!("{RUN_FILE}.partial"));
    let fail =
        |e: io::Error| io::Error::new(e.kind(), format!("cannot write {}: {e}", path.display()));
    let mut file = std::fs::File::create(&partial).map_err(fail)?;
    writeln!(file, "{run:016x}")
        .and_then(|()| file.sync_all())
        .map_err(fail)?;
    std::fs::rename(&partial, &path).map_err(fail)
}

/// The identity a restart from a checkpoint of run `checkpoint_run` (`None`: a file without one) continues
/// under in `dir`, recorded there; refused when `dir` holds another run's outputs.
pub fn continue_in(dir: &Path, checkpoint_run: Option<u64>, checkpoint: &Path) -> io::Result<u64> {
    let refuse = |what: String| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} holds the outputs of run {what}; restart into that run's directory or give a new --out",
                dir.display()
            ),
        )
    };
    match (recorded(dir)?, checkpoint_run) {
        (Some(here), Some(run)) if here != run => Err(refuse(format!(
            "{here:016x}, and {} belongs to run {run:016x}",
            checkpoint.display()
        ))),
        (Some(here), None) => Err(refuse(format!(
            "{here:016x}, and {} carries no run identity (written before runs had one)",
            checkpoint.display()
        ))),
        (_, run) => {
            let run = run.unwrap_or_else(new_run);
            record(dir, run)?;
            Ok(run)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{continue_in, new_run, record, recorded};

    #[test]
    fn a_restart_is_accepted_only_into_its_own_runs_directory() {
        let dir = std::env::temp_dir().join(format!("polydem-run-id-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let checkpoint = dir.join("step_1.pdck");
        assert_eq!(recorded(&dir).unwrap(), None);
        let (a, b) = (new_run(), new_run() ^ 1);
        assert_eq!(
            continue_in(&dir, Some(a), &checkpoint).unwrap(),
            a,
            "an empty directory"
        );
        assert_eq!(recorded(&dir).unwrap(), Some(a));
        assert_eq!(
            continue_in(&dir, Some(a), &checkpoint).unwrap(),
            a,
            "its own run"
        );
        let other = continue_in(&dir, Some(b), &checkpoint).expect_err("another run's checkpoint");
        assert!(
            other.to_string().contains("holds the outputs of run"),
            "{other}"
        );
        let old = continue_in(&dir, None, &checkpoint).expect_err("a checkpoint without identity");
        assert!(old.to_string().contains("carries no run identity"), "{old}");
        record(&dir, b).unwrap();
        assert_eq!(
            recorded(&dir).unwrap(),
            Some(b),
            "a fresh run records its own"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
