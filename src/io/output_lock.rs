//! One run at a time per output directory: a run holds an exclusive advisory lock (`flock`) on
//! `DIR/.polydem.lock` while it writes there, so a second run into the same directory is refused instead
//! of interleaving its rows with the first's. The lock goes with the process (closed file, ended process),
//! so a killed run leaves nothing to clean up.

use std::fs::{File, OpenOptions};
use std::io;
use std::os::fd::AsRawFd;
use std::path::{Path, PathBuf};

/// The name of the lock file in an output directory.
pub const LOCK_FILE: &str = ".polydem.lock";

/// An exclusive lock on an output directory, released when dropped.
#[derive(Debug)]
pub struct DirectoryLock {
    _file: File,
    path: PathBuf,
}

impl DirectoryLock {
    /// Locks `dir` (which must exist) or fails at once, naming the directory, if another process holds it.
    pub fn acquire(dir: &Path) -> io::Result<Self> {
        let path = dir.join(LOCK_FILE);
        let file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(|e| {
                io::Error::new(e.kind(), format!("cannot open {}: {e}", path.display()))
            })?;
        // SAFETY: flock on a file descriptor this function owns for the call's duration.
        let status = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
        if status != 0 {
            let e = io::Error::last_os_error();
            return Err(if e.kind() == io::ErrorKind::WouldBlock {
                io::Error::new(
                    io::ErrorKind::WouldBlock,
                    format!(
                        "another run is writing into {} (it holds {}); give another --out",
                        dir.display(),
                        path.display()
                    ),
                )
            } else {
                io::Error::new(e.kind(), format!("cannot lock {}: {e}", path.display()))
            });
        }
        Ok(Self { _file: file, path })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::DirectoryLock;

    #[test]
    fn a_second_lock_on_a_directory_is_refused_until_the_first_is_dropped() {
        let dir = std::env::temp_dir().join(format!("polydem-lock-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let first = DirectoryLock::acquire(&dir).expect("first lock");
        let second = DirectoryLock::acquire(&dir);
        let message = second
            .expect_err("a second lock while the first is held")
            .to_string();
        assert!(message.contains("another run is writing into"), "{message}");
        drop(first);
        DirectoryLock::acquire(&dir).expect("the lock after the first was dropped");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
