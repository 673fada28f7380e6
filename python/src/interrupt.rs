//! Ctrl-C during a long call. The engine runs with the GIL released, and Python runs its signal handlers
//! only when the main thread asks (`PyErr_CheckSignals`), so a long run checks for them itself: the run
//! loop calls its observer's `progress` at least every [`PROGRESS_STEPS`] steps, the rockfill experiment
//! its stop check before every step, and there, at most every [`CHECK_INTERVAL`], the GIL is taken
//! briefly and the handlers run. When one raises (`KeyboardInterrupt` for SIGINT), the run ends at the
//! next step boundary and the exception is raised.
//!
//! [`PROGRESS_STEPS`]: polydem::scene::PROGRESS_STEPS

use std::io;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use polydem::scene::{RunObserver, Simulation};
use polydem_rockfill::stop::StopCheck;
use pyo3::prelude::*;

/// How often a run gives Python its signals: short beside a human's patience, long beside the few
/// microseconds that taking the GIL costs.
pub const CHECK_INTERVAL: Duration = Duration::from_millis(100);

/// Python's signal handlers, run from inside a call that released the GIL.
pub struct SignalCheck {
    last: Instant,
    raised: Option<PyErr>,
    /// Python runs signal handlers on its main thread only, so a call from another thread never takes
    /// the GIL for them.
    on_main_thread: bool,
}

impl SignalCheck {
    /// A check for a call made by the current thread (`py` held by it).
    pub fn new(py: Python<'_>) -> Self {
        Self {
            last: Instant::now(),
            raised: None,
            on_main_thread: is_main_thread(py),
        }
    }

    /// Runs the signal handlers if [`CHECK_INTERVAL`] has passed since they last ran; whether one has
    /// raised (now or before).
    pub fn poll(&mut self) -> bool {
        if self.on_main_thread && self.raised.is_none() && self.last.elapsed() >= CHECK_INTERVAL {
            self.raised = Python::attach(|py| py.check_signals().err());
            self.last = Instant::now();
        }
        self.raised.is_some()
    }

    /// The exception a handler raised, if one did (taken: the next call answers `None`).
    pub fn take_raised(&mut self) -> Option<PyErr> {
        self.raised.take()
    }
}

/// Whether the calling thread is Python's main thread (when `threading` cannot tell, it is taken to be,
/// so that the handlers are still run).
fn is_main_thread(py: Python<'_>) -> bool {
    let answer = || -> PyResult<bool> {
        let threading = py.import("threading")?;
        let main = threading.call_method0("main_thread")?;
        let current = threading.call_method0("current_thread")?;
        Ok(main.is(&current))
    };
    answer().unwrap_or(true)
}

/// A check for the rockfill experiment, which asks it before each step, and the [`SignalCheck`] that
/// answers it (to take the exception from after the run).
pub fn stop_check(py: Python<'_>) -> (StopCheck, Arc<Mutex<SignalCheck>>) {
    let signals = Arc::new(Mutex::new(SignalCheck::new(py)));
    let shared = Arc::clone(&signals);
    let stop = StopCheck::new(move || shared.lock().is_ok_and(|mut s| s.poll()));
    (stop, signals)
}

/// The exception that stopped a rockfill run (a signal handler's, or one [`record`]ed), if one did.
pub fn raised(signals: &Mutex<SignalCheck>) -> Option<PyErr> {
    signals.lock().ok()?.take_raised()
}

/// Whether an exception has been raised during the run (it stops at its next step).
pub fn raised_already(signals: &Mutex<SignalCheck>) -> bool {
    signals.lock().is_ok_and(|s| s.raised.is_some())
}

/// An exception raised during a rockfill run by Python code it called (the progress callback): it stops
/// the run as a signal handler's does (the first one raised is kept).
pub fn record(signals: &Mutex<SignalCheck>, e: PyErr) {
    if let Ok(mut s) = signals.lock() {
        s.raised.get_or_insert(e);
    }
}

/// An observer of a run that also gives Python its signals (in `progress`). Once a handler has raised,
/// it asks for the whole state (bodies and contacts) at the next step and fails that observation with
/// [`io::ErrorKind::Interrupted`]: the run loop then stops there with the world written back and
/// consistent, as after any observed step.
pub struct Interruptible<'s, O> {
    pub inner: O,
    pub signals: &'s mut SignalCheck,
}

impl<O: RunObserver> RunObserver for Interruptible<'_, O> {
    fn wants_state(&self, step: u64) -> bool {
        self.signals.raised.is_some() || self.inner.wants_state(step)
    }
    fn observe(&mut self, sim: &Simulation, step: u64) -> io::Result<()> {
        if self.signals.raised.is_some() {
            return Err(io::Error::new(
                io::ErrorKind::Interrupted,
                "the run was interrupted",
            ));
        }
        self.inner.observe(sim, step)
    }
    fn progress(&mut self, step: u64) {
        self.inner.progress(step);
        self.signals.poll();
    }
    fn reads_contacts(&self, step: u64) -> bool {
        self.signals.raised.is_some() || self.inner.reads_contacts(step)
    }
}
