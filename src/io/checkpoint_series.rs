//! Checkpoints of a run (`DIR/checkpoints/step_NNNNNNNNN.pdck`, format in [`super::checkpoint`]) as an
//! [`Output`] that marks restart points.

use std::io;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::io::checkpoint;
use crate::io::output::{Output, Schedule};
use crate::io::run_summary::{CheckpointRecord, OutputRecord};
use crate::scene::Simulation;

/// Checkpoints written on a schedule into `DIR/checkpoints/`.
pub struct CheckpointSeries {
    out_dir: PathBuf,
    run: u64,
    schedule: Schedule,
    written: Vec<CheckpointRecord>,
    time: Duration,
}

impl CheckpointSeries {
    /// Checkpoints of run `run` ([`crate::io::run_identity`]); creates `out_dir/checkpoints/` if needed.
    pub fn new(out_dir: &Path, run: u64, schedule: Schedule) -> io::Result<Self> {
        let dir = out_dir.join("checkpoints");
        std::fs::create_dir_all(&dir).map_err(|e| {
            io::Error::new(e.kind(), format!("cannot create {}: {e}", dir.display()))
        })?;
        Ok(Self {
            out_dir: out_dir.to_owned(),
            run,
            schedule,
            written: Vec::new(),
            time: Duration::ZERO,
        })
    }
}

impl Output for CheckpointSeries {
    fn due(&self, step: u64) -> bool {
        self.schedule.due(step)
    }

    fn reads_contacts(&self) -> bool {
        true
    }

    fn marks_restart_point(&self) -> bool {
        true
    }

    fn write(&mut self, sim: &Simulation, step: u64) -> io::Result<()> {
        let start = Instant::now();
        let file = format!("checkpoints/step_{step:09}.pdck");
        let bytes = checkpoint::save_in_run(&self.out_dir.join(&file), sim, Some(self.run))
            .map_err(io::Error::other)?;
        let seconds = start.elapsed();
        self.time += seconds;
        self.written.push(CheckpointRecord {
            file,
            step,
            time: sim.world.time(),
            bytes,
            seconds: seconds.as_secs_f64(),
        });
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        // Each checkpoint is written whole to a temporary file and renamed.
        Ok(())
    }

    fn record(&self, record: &mut OutputRecord) {
        record.checkpoint_every = self.schedule.every;
        record.checkpoints.extend(self.written.iter().cloned());
        record.checkpoint_time += self.time;
    }
}
