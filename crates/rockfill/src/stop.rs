//! A way to stop a long run early: a check the packing and the penetration runs call once per time step,
//! before the step. A front end answers it (the Python package runs its signal handlers there, so that
//! Ctrl-C reaches a run that holds no GIL); a run told to stop ends with an `Interrupted` error at a step
//! boundary.

use std::fmt;
use std::sync::Arc;

/// Asked before each step whether the run should stop there.
#[derive(Clone)]
pub struct StopCheck(Arc<dyn Fn() -> bool + Send + Sync>);

impl StopCheck {
    /// A check answered by `should_stop`; it is called once per step, so it should be cheap most times.
    pub fn new(should_stop: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        Self(Arc::new(should_stop))
    }

    /// Whether the run should stop before its next step.
    pub fn should_stop(&self) -> bool {
        (self.0)()
    }
}

/// Whether a run holding `stop` (if any) should stop before its next step.
pub fn requested(stop: Option<&StopCheck>) -> bool {
    stop.is_some_and(StopCheck::should_stop)
}

impl fmt::Debug for StopCheck {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("StopCheck")
    }
}

/// Two checks are equal when they are the same check (options compare by what they would do).
impl PartialEq for StopCheck {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}
