//! `polydem-mpi-scaling`: weak and strong scaling of distributed runs on this machine, the ping-pong of
//! its MPI, the cost model extrapolated to clusters, and the report page `reports/mpi.md`.
//!
//! One command runs the whole set and writes the page (about 5 minutes on 2 cores; run it when the
//! machine is otherwise idle, the page says which runs were not):
//!
//! `MPI_PKG_CONFIG=mpich cargo run --release -p polydem-mpi --features mpi --bin polydem-mpi-scaling -- drive`
//!
//! Modes:
//! - `drive [--repeats R] [--out DIR]`: launches every run under `mpirun.mpich` (or `$POLYDEM_MPIRUN`)
//!   with `RAYON_NUM_THREADS=1`, then the ping-pong, times the plan, and writes the page (`DIR` =
//!   `reports`, R = 3).
//! - `report [--out DIR]`: writes the page again from `DIR/mpi/*.csv`.
//! - `measure --run ID --scene spheres|polyhedra --nx --ny --nz --steps --csv FILE` (under `mpirun`):
//!   one run; rank 0 appends a row per rank to `FILE`.
//! - `pingpong --csv FILE` (under `mpirun -n 2`): half round trips of messages of 8 B to 1 MiB.

mod drive;
mod extrapolate;
mod measure;
mod pingpong;
mod plot;
mod report;

use std::collections::HashMap;
use std::path::PathBuf;
use std::process::ExitCode;

/// The tool's errors, as text for the terminal.
type Error = Box<dyn std::error::Error>;

/// `--key value` pairs after the mode.
struct Args(HashMap<String, String>);

impl Args {
    fn parse(words: &[String]) -> Result<Self, Error> {
        let mut map = HashMap::new();
        let mut it = words.iter();
        while let Some(key) = it.next() {
            let name = key
                .strip_prefix("--")
                .ok_or_else(|| format!("expected --key, got `{key}`"))?;
            let value = it.next().ok_or_else(|| format!("--{name} needs a value"))?;
            map.insert(name.to_owned(), value.clone());
        }
        Ok(Self(map))
    }

    fn text(&self, key: &str) -> Result<&str, Error> {
        self.0
            .get(key)
            .map(String::as_str)
            .ok_or_else(|| format!("--{key} is required").into())
    }

    fn number<T: std::str::FromStr>(&self, key: &str) -> Result<T, Error>
    where
        T::Err: std::fmt::Display,
    {
        let text = self.text(key)?;
        text.parse()
            .map_err(|e| format!("--{key} `{text}`: {e}").into())
    }

    fn path_or(&self, key: &str, default: &str) -> PathBuf {
        PathBuf::from(self.0.get(key).map(String::as_str).unwrap_or(default))
    }
}

fn run(words: &[String]) -> Result<(), Error> {
    let (mode, rest) = words
        .split_first()
        .ok_or("usage: polydem-mpi-scaling drive|report|measure|pingpong [--key value …]")?;
    let args = Args::parse(rest)?;
    match mode.as_str() {
        "drive" => {
            let repeats = if args.0.contains_key("repeats") {
                args.number("repeats")?
            } else {
                3
            };
            drive::drive(&args.path_or("out", "reports"), repeats)
        }
        "report" => report::write(&args.path_or("out", "reports")),
        "measure" => measure::measure(&measure::Spec::from_args(&args)?),
        "pingpong" => pingpong::pingpong(&args.path_or("csv", "pingpong.csv")),
        other => Err(format!("unknown mode `{other}` (drive, report, measure, pingpong)").into()),
    }
}

fn main() -> ExitCode {
    let words: Vec<String> = std::env::args().skip(1).collect();
    match run(&words) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("polydem-mpi-scaling: {e}");
            ExitCode::FAILURE
        }
    }
}
