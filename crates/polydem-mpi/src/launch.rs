//! Starting a program on P ranks: MPICH's Hydra launcher `mpirun.mpich`, or the launcher named by
//! `$POLYDEM_MPIRUN` (Open MPI is installed beside MPICH on Debian machines with YADE, and its `mpirun`
//! refuses to run as root without extra variables). Used by the tests that launch themselves and by the
//! scaling tool.

use std::ffi::OsStr;
use std::process::Command;
use std::time::Instant;

/// The environment variable that names the launcher.
pub const MPIRUN_VARIABLE: &str = "POLYDEM_MPIRUN";

/// The launcher: `$POLYDEM_MPIRUN`, else `mpirun.mpich`.
pub fn mpirun() -> String {
    std::env::var(MPIRUN_VARIABLE).unwrap_or_else(|_| "mpirun.mpich".to_owned())
}

/// `mpirun -n ranks program`, to which the caller adds arguments and environment.
pub fn command(ranks: usize, program: impl AsRef<OsStr>) -> Command {
    let mut command = Command::new(mpirun());
    command.args(["-n", &ranks.to_string()]).arg(program);
    command
}

/// Runs `program` on each rank count of `ranks` in turn, set up by `configure`, printing each launch's
/// status and time under `label`; returns a line per launch that did not succeed.
pub fn launch_each(
    label: &str,
    ranks: &[usize],
    program: impl AsRef<OsStr>,
    configure: impl Fn(&mut Command),
) -> Vec<String> {
    let mut failures = Vec::new();
    for &n in ranks {
        let start = Instant::now();
        let mut launch = command(n, program.as_ref());
        configure(&mut launch);
        let status = launch
            .status()
            .unwrap_or_else(|e| panic!("{} could not be started: {e}", mpirun()));
        println!(
            "{label}, {n} ranks: {status} in {:.1} s",
            start.elapsed().as_secs_f64()
        );
        if !status.success() {
            failures.push(format!("{label} on {n} ranks: {status}"));
        }
    }
    failures
}
