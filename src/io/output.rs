//! The outputs of a run behind one trait: CSV series, VTK frames, checkpoints, the contact network.
//!
//! A run hands its state to an [`OutputSet`] (a [`RunObserver`]) only at the steps some output is due, so
//! the pipeline may step on a layout of its own in between. Each [`Output`] says when it is due, whether it
//! reads the contact store, and how to write, flush and account for itself; the set adds the ordering rule
//! every restartable run needs: before an output that marks a restart point (a checkpoint) writes, every
//! other output is flushed and synced, so the series on disk reach at least as far as the checkpoint
//! whatever moment the run is killed at, and a restart from it continues them (rows after it dropped).
//!
//! The trait sees the whole [`Simulation`]: an implementation that gathers pieces from several processes
//! (CSV from one rank, VTK as parallel pieces) keeps the same interface.

use std::io;
use std::time::Instant;

use crate::io::output_lock::DirectoryLock;
use crate::io::run_summary::OutputRecord;
use crate::scene::{RunObserver, Simulation};

/// One output of a run.
pub trait Output {
    /// Whether it writes the state after step `step` (counted from step 0).
    fn due(&self, step: u64) -> bool;
    /// Whether it reads the contact store or the broad phase when it writes (else the pipeline may hand
    /// it a world whose contact store is that of an earlier step).
    fn reads_contacts(&self) -> bool {
        false
    }
    /// Whether what it writes is a point a run restarts from: every other output is flushed first.
    fn marks_restart_point(&self) -> bool {
        false
    }
    /// Writes the state after step `step`.
    fn write(&mut self, sim: &Simulation, step: u64) -> io::Result<()>;
    /// Makes everything written so far durable: written to its files and synced to the disk.
    fn flush(&mut self) -> io::Result<()>;
    /// Adds what it wrote (files, bytes, time) to the run's record.
    fn record(&self, record: &mut OutputRecord);
}

/// When an output is due: at the first step of the run, every `every` steps, and at the last step.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Schedule {
    /// The step the run starts from.
    pub start_step: u64,
    /// The step the run ends at.
    pub last_step: u64,
    /// Steps between writes; `None`: only at the start and the end (if those are enabled).
    pub every: Option<u64>,
    /// Whether it writes the state the run starts from.
    pub at_start: bool,
    /// Whether it writes the state the run ends with.
    pub at_end: bool,
}

impl Schedule {
    /// Whether step `step` is a write.
    pub fn due(&self, step: u64) -> bool {
        if step == self.start_step {
            return self.at_start;
        }
        self.every.is_some_and(|k| step.is_multiple_of(k))
            || (self.at_end && step == self.last_step)
    }
}

/// The outputs of one run, in the order they write at a step, plus a progress callback. It can be sent to
/// another thread (a front door may run the loop off its own thread, as Python does without the GIL).
pub struct OutputSet<'a> {
    outputs: Vec<Box<dyn Output + Send + 'a>>,
    progress: Box<dyn FnMut(u64) + Send + 'a>,
    record: OutputRecord,
    lock: Option<DirectoryLock>,
}

impl<'a> OutputSet<'a> {
    /// A set with no outputs and no progress report.
    pub fn new() -> Self {
        Self {
            outputs: Vec::new(),
            progress: Box::new(|_| {}),
            record: OutputRecord::default(),
            lock: None,
        }
    }

    /// Keeps the lock of the output directory until the set is finished or dropped.
    pub fn hold(&mut self, lock: DirectoryLock) {
        self.lock = Some(lock);
    }

    /// Adds an output; outputs write in the order they were added.
    pub fn push(&mut self, output: impl Output + Send + 'a) {
        self.outputs.push(Box::new(output));
    }

    /// Called with the number of steps done (from step 0) as the run goes.
    pub fn on_progress(&mut self, progress: impl FnMut(u64) + Send + 'a) {
        self.progress = Box::new(progress);
    }

    /// Flushes every output and returns the record of what was written.
    pub fn finish(mut self) -> io::Result<OutputRecord> {
        let start = Instant::now();
        for output in &mut self.outputs {
            output.flush()?;
        }
        self.record.time += start.elapsed();
        for output in &self.outputs {
            output.record(&mut self.record);
        }
        drop(self.lock.take());
        Ok(self.record)
    }
}

impl Default for OutputSet<'_> {
    fn default() -> Self {
        Self::new()
    }
}

impl RunObserver for OutputSet<'_> {
    fn wants_state(&self, step: u64) -> bool {
        self.outputs.iter().any(|o| o.due(step))
    }

    fn observe(&mut self, sim: &Simulation, step: u64) -> io::Result<()> {
        let start = Instant::now();
        for k in 0..self.outputs.len() {
            if !self.outputs[k].due(step) {
                continue;
            }
            if self.outputs[k].marks_restart_point() {
                for other in &mut self.outputs {
                    other.flush()?;
                }
            }
            self.outputs[k].write(sim, step)?;
        }
        self.record.time += start.elapsed();
        Ok(())
    }

    fn progress(&mut self, step: u64) {
        (self.progress)(step);
    }

    fn reads_contacts(&self, step: u64) -> bool {
        self.outputs
            .iter()
            .any(|o| o.due(step) && o.reads_contacts())
    }
}

#[cfg(test)]
mod tests {
    use super::Schedule;

    #[test]
    fn a_schedule_writes_at_the_start_every_k_steps_and_at_the_end() {
        let s = Schedule {
            start_step: 3,
            last_step: 11,
            every: Some(4),
            at_start: true,
            at_end: true,
        };
        let due: Vec<u64> = (3..=11).filter(|&n| s.due(n)).collect();
        assert_eq!(due, vec![3, 4, 8, 11], "schedule {s:?}");
        let checkpoints = Schedule {
            at_start: false,
            ..s
        };
        let due: Vec<u64> = (3..=11).filter(|&n| checkpoints.due(n)).collect();
        assert_eq!(due, vec![4, 8, 11], "schedule {checkpoints:?}");
        let never = Schedule {
            every: None,
            at_start: false,
            at_end: false,
            ..s
        };
        assert!((3..=11).all(|n| !never.due(n)), "schedule {never:?}");
    }
}
