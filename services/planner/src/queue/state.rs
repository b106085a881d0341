//! The queue of one instance: its settings, its state behind a lock, and what it
//! tells about its load.

use std::sync::Mutex;

use super::rate::{Rate, PRIOR_SECONDS_PER_UNIT};
use super::rounds::Inner;

/// The queue's settings (see [`crate::PlannerConfig`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QueueConfig {
    pub max_concurrent_plans: usize,
    pub max_queued_plans: usize,
}

/// The queue of one instance.
#[derive(Debug)]
pub struct PlanQueue {
    pub(super) config: QueueConfig,
    inner: Mutex<Inner>,
    pub(super) changed: tokio::sync::Notify,
}

impl PlanQueue {
    pub fn new(config: QueueConfig) -> Self {
        let shared = config.max_concurrent_plans.max(1) as f64;
        PlanQueue {
            config,
            inner: Mutex::new(Inner {
                rate: Rate {
                    seconds_per_unit: PRIOR_SECONDS_PER_UNIT * shared,
                    samples: 0,
                },
                ..Inner::default()
            }),
            changed: tokio::sync::Notify::new(),
        }
    }

    pub(super) fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        roam_runtime::lock(&self.inner)
    }

    pub fn config(&self) -> QueueConfig {
        self.config
    }

    /// The measured rate.
    pub fn rate(&self) -> Rate {
        self.lock().rate
    }

    /// Plans running and plans queued.
    pub fn load(&self) -> (usize, usize) {
        let inner = self.lock();
        (inner.running.len(), inner.waiting.len())
    }

    /// Seconds a plan of `units` is expected to take, at most `cap_s`.
    pub fn expected_plan_s(&self, units: f64, cap_s: f64) -> f64 {
        (units * self.lock().rate.seconds_per_unit).min(cap_s)
    }
}
