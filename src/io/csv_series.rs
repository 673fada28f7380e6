//! The CSV series of a run (`bodies.csv`, `energy.csv`, `walls.csv`; columns in [`super::csv_output`]) as
//! an [`Output`].

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::io::csv_continue::{continue_csv, rows_before};
use crate::io::csv_output;
use crate::io::output::{Output, Schedule};
use crate::io::run_summary::OutputRecord;
use crate::scene::Simulation;
use crate::world::EnergyReport;

/// The three series, written at the same steps.
pub struct CsvSeries {
    files: [(PathBuf, BufWriter<File>); 3],
    schedule: Schedule,
}

const SERIES: [(&str, &str); 3] = [
    ("bodies.csv", csv_output::BODIES_HEADER),
    ("energy.csv", EnergyReport::CSV_HEADER),
    ("walls.csv", csv_output::WALLS_HEADER),
];

impl CsvSeries {
    /// New series in `dir`, each starting with its header.
    pub fn create(dir: &Path, schedule: Schedule) -> io::Result<Self> {
        Self::open(dir, schedule, |path, header| {
            let file = File::create(path).map_err(|e| in_file(path, "cannot create", e))?;
            let mut out = BufWriter::new(file);
            writeln!(out, "{header}")?;
            Ok(out)
        })
    }

    /// Continues the series an earlier run left in `dir`: rows before `start_time` are kept, later ones
    /// dropped (see [`continue_csv`]). Every series is checked before any is rewritten, so a refused
    /// restart leaves the directory as it was.
    pub fn continue_at(dir: &Path, start_time: f64, schedule: Schedule) -> io::Result<Self> {
        for (name, header) in SERIES {
            let path = dir.join(name);
            match std::fs::read_to_string(&path) {
                Ok(text) => {
                    rows_before(&text, header, start_time).map_err(|(line, what)| {
                        io::Error::new(
                            io::ErrorKind::InvalidData,
                            format!("cannot continue {}:{line}: {what}", path.display()),
                        )
                    })?;
                }
                Err(e) if e.kind() == io::ErrorKind::NotFound => {}
                Err(e) => return Err(in_file(&path, "cannot read", e)),
            }
        }
        Self::open(dir, schedule, |path, header| {
            continue_csv(path, header, start_time).map_err(|e| in_file(path, "cannot continue", e))
        })
    }

    fn open(
        dir: &Path,
        schedule: Schedule,
        mut open_one: impl FnMut(&Path, &str) -> io::Result<BufWriter<File>>,
    ) -> io::Result<Self> {
        let mut open = |k: usize| -> io::Result<(PathBuf, BufWriter<File>)> {
            let path = dir.join(SERIES[k].0);
            let out = open_one(&path, SERIES[k].1)?;
            Ok((path, out))
        };
        Ok(Self {
            files: [open(0)?, open(1)?, open(2)?],
            schedule,
        })
    }
}

fn in_file(path: &Path, what: &str, e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{what} {}: {e}", path.display()))
}

impl Output for CsvSeries {
    fn due(&self, step: u64) -> bool {
        self.schedule.due(step)
    }

    fn write(&mut self, sim: &Simulation, _step: u64) -> io::Result<()> {
        let [bodies, energy, walls] = &mut self.files;
        csv_output::write_bodies_rows(&mut bodies.1, sim)?;
        csv_output::write_walls_rows(&mut walls.1, sim)?;
        csv_output::write_energy_row(&mut energy.1, sim)
    }

    fn flush(&mut self) -> io::Result<()> {
        for (path, out) in &mut self.files {
            out.flush().map_err(|e| in_file(path, "writing", e))?;
        }
        Ok(())
    }

    fn record(&self, record: &mut OutputRecord) {
        record.csv_every = self.schedule.every.unwrap_or(0);
    }
}
