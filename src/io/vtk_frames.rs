//! VTK frames of a run ([`super::vtk::VtkWriter`]) as an [`Output`].

use std::io;
use std::time::{Duration, Instant};

use crate::io::output::{Output, Schedule};
use crate::io::run_summary::OutputRecord;
use crate::io::vtk::VtkWriter;
use crate::scene::Simulation;

/// VTK frames with their `.pvd` collections, written on a schedule.
pub struct VtkFrames {
    writer: VtkWriter,
    schedule: Schedule,
    time: Duration,
}

impl VtkFrames {
    /// Frames from `writer` (new or resumed) at the steps of `schedule`.
    pub fn new(writer: VtkWriter, schedule: Schedule) -> Self {
        Self {
            writer,
            schedule,
            time: Duration::ZERO,
        }
    }
}

impl Output for VtkFrames {
    fn due(&self, step: u64) -> bool {
        self.schedule.due(step)
    }

    fn write(&mut self, sim: &Simulation, _step: u64) -> io::Result<()> {
        let start = Instant::now();
        self.writer
            .write_frame(&sim.world)
            .map_err(|e| io::Error::new(e.kind(), format!("writing VTK frames: {e}")))?;
        self.time += start.elapsed();
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        // Each frame and collection is a whole file written at once.
        Ok(())
    }

    fn record(&self, record: &mut OutputRecord) {
        record.vtk_every = self.schedule.every;
        record.vtk_frames = self.writer.frames_written;
        record.vtk_bytes = self.writer.bytes_written;
        record.vtk_time += self.time;
    }
}
