//! A request admitted: its turn waited for, its plan's end measured, its place freed
//! when dropped.

use std::time::{Duration, Instant};

use tokio_util::sync::CancellationToken;

use super::rate::OVERHEAD_UNITS;
use super::state::PlanQueue;

/// A request admitted to the queue; it leaves the queue when dropped (cancelled,
/// refused later, or done).
#[derive(Debug)]
pub struct Ticket<'a> {
    pub(super) queue: &'a PlanQueue,
    pub(super) id: u64,
    /// When it arrived: its deadline counts from here.
    pub arrived: Instant,
    pub expected_wait_s: f64,
    pub expected_plan_s: f64,
    /// Whether it had to queue (no slot was free for it on arrival).
    pub queued: bool,
    pub(super) units: f64,
    pub(super) started: Option<Instant>,
}

/// What [`Ticket::wait_turn`] ended with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Turn {
    /// A slot is this request's: plan now.
    Plan,
    /// The requester cancelled (or the instance is stopping) while it was queued.
    Cancelled,
    /// The queue was full and a request of an earlier round took this one's place.
    Displaced,
}

impl Ticket<'_> {
    /// Moves this request from the queue to a slot if it is first in line and a slot
    /// is free.
    pub(super) fn try_start(&mut self, now: Instant) -> Option<Turn> {
        let queue = self.queue;
        let mut inner = queue.lock();
        if inner.displaced.remove(&self.id) {
            return Some(Turn::Displaced);
        }
        let first = inner.waiting.front().is_some_and(|j| j.id == self.id);
        if !first || inner.running.len() >= queue.config.max_concurrent_plans {
            return None;
        }
        if let Some(mut job) = inner.waiting.pop_front() {
            job.since = now;
            inner.round = inner.round.max(job.round);
            inner.running.push(job);
            self.started = Some(now);
        }
        Some(Turn::Plan)
    }

    /// Waits until a slot is this request's, in its client's fair turn, or until
    /// `cancel`, or until it is displaced.
    pub async fn wait_turn(&mut self, cancel: &CancellationToken) -> Turn {
        loop {
            let changed = self.queue.changed.notified();
            tokio::pin!(changed);
            // Registered before the check, so no wake-up between them is lost.
            changed.as_mut().enable();
            if let Some(turn) = self.try_start(Instant::now()) {
                return turn;
            }
            tokio::select! {
                _ = &mut changed => {}
                _ = cancel.cancelled() => {
                    return Turn::Cancelled;
                }
            }
        }
    }

    /// When it left the queue for a slot.
    pub fn started(&self) -> Option<Instant> {
        self.started
    }

    /// Ends a plan that did `share` (0..=1) of its generations: the rate learns from
    /// its wall time over the units it did ([`OVERHEAD_UNITS`] and that share of the
    /// rest). Dropping the ticket frees the slot.
    pub fn finish(self, share: f64, now: Instant) {
        if let Some(started) = self.started {
            let seconds = now.saturating_duration_since(started).as_secs_f64();
            let work = (self.units - OVERHEAD_UNITS).max(0.0);
            let done = OVERHEAD_UNITS + work * share.clamp(0.0, 1.0);
            self.queue.lock().rate.measure(done, seconds);
        }
    }

    /// Seconds of its deadline left at `now`.
    pub fn remaining_s(&self, deadline_s: f64, now: Instant) -> f64 {
        deadline_s - now.saturating_duration_since(self.arrived).as_secs_f64()
    }

    /// How long it waited in the queue.
    pub fn waited(&self) -> Duration {
        self.started.map_or(Duration::ZERO, |s| {
            s.saturating_duration_since(self.arrived)
        })
    }
}

impl Drop for Ticket<'_> {
    fn drop(&mut self) {
        let mut inner = self.queue.lock();
        inner.remove(self.id);
        drop(inner);
        self.queue.changed.notify_waiters();
    }
}
