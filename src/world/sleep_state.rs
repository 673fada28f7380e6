//! The data of sleeping: its settings and the per-body state the world keeps (see [`super::sleeping`] for
//! what the thresholds mean and the stages that put bodies to sleep and wake them).

use crate::math::{Real, Vector};

/// The settings of sleeping (see the module docs for what each threshold means and why its default).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SleepParams {
    /// Whether bodies may fall asleep.
    pub enabled: bool,
    /// Rest speed as a fraction of √(|g| d).
    pub rest_speed: Real,
    /// Rest force as a fraction of the weight m |g| (and rest torque of m |g| r); also the departure from
    /// the rest load that wakes a sleeping body.
    pub rest_force: Real,
    /// Consecutive calm steps before a body falls asleep.
    pub steps: u32,
    /// Wake threshold as a fraction of the sum of the contact force magnitudes Σ|f| of the body at rest,
    /// when that is larger than `rest_force` of the weight (0: the weight alone sets it; see the module docs).
    pub wake_contact_fraction: Real,
}

/// Default [`SleepParams::rest_speed`] (see the module docs).
pub const DEFAULT_REST_SPEED: Real = 1e-3;
/// Default [`SleepParams::rest_force`] (see the module docs).
pub const DEFAULT_REST_FORCE: Real = 1e-2;
/// Default [`SleepParams::steps`] (see the module docs).
pub const DEFAULT_SLEEP_STEPS: u32 = 200;

impl Default for SleepParams {
    /// Off, with the default thresholds.
    fn default() -> Self {
        Self {
            enabled: false,
            rest_speed: DEFAULT_REST_SPEED,
            rest_force: DEFAULT_REST_FORCE,
            steps: DEFAULT_SLEEP_STEPS,
            wake_contact_fraction: 0.0,
        }
    }
}

impl SleepParams {
    /// On, with the default thresholds.
    pub fn on() -> Self {
        Self {
            enabled: true,
            ..Self::default()
        }
    }
}

/// Per-body sleeping state, kept in the world.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SleepState {
    /// Whether each body is asleep.
    pub(in crate::world) asleep: Vec<bool>,
    /// Consecutive calm steps of each awake body.
    pub(in crate::world) calm_steps: Vec<u32>,
    /// Number of sleeping bodies.
    pub(in crate::world) sleeping: usize,
    /// Rest load of each sleeping body: net force F + m g (N) when it fell asleep.
    pub(in crate::world) rest_force: Vec<Vector>,
    /// Contact torque of each sleeping body when it fell asleep (N·m).
    pub(in crate::world) rest_torque: Vec<Vector>,
    /// Departure of the net force (N) from the rest load that wakes each sleeping body (of the torque:
    /// this times its bounding radius).
    pub(in crate::world) wake_limit: Vec<Real>,
    /// Counts every change of the sleeping set (the frozen sums are rebuilt when it moves).
    pub(in crate::world) changes: u64,
}

impl SleepState {
    /// Makes the state cover `n` bodies (new bodies are awake).
    pub(crate) fn resize(&mut self, n: usize) {
        self.asleep.resize(n, false);
        self.calm_steps.resize(n, 0);
        self.rest_force.resize(n, Vector::zeros());
        self.rest_torque.resize(n, Vector::zeros());
        self.wake_limit.resize(n, 0.0);
    }

    /// Number of sleeping bodies.
    pub fn asleep_count(&self) -> usize {
        self.sleeping
    }

    /// Whether body `i` is asleep (false for an index the state does not cover yet).
    pub fn is_asleep(&self, i: usize) -> bool {
        self.asleep.get(i).copied().unwrap_or(false)
    }

    /// Every body awake (sleeping switched off); the change counter keeps counting.
    pub(crate) fn wake_all(&mut self) -> usize {
        let woken = self.sleeping;
        let changes = self.changes + 1;
        let n = self.asleep.len();
        *self = Self {
            changes,
            ..Self::default()
        };
        self.resize(n);
        woken
    }

    pub(super) fn wake(&mut self, i: usize) {
        self.asleep[i] = false;
        self.calm_steps[i] = 0;
        self.sleeping -= 1;
        self.changes += 1;
    }
}

/// What one sleeping update did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SleepCounts {
    /// Bodies that fell asleep.
    pub fell_asleep: u64,
    /// Bodies woken.
    pub woken: u64,
}
