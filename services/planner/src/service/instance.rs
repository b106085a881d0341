//! What a planner instance's queryables and subscribers share, and its wire limits.

use std::collections::BTreeSet;
use std::sync::atomic::AtomicU64;
use std::sync::{Mutex, MutexGuard};
use std::time::Duration;

use roam_runtime::warn_limit::WarnLimiter;

use crate::budget::CpuBudget;
use crate::inflight::InFlight;
use crate::limits::PlanLimits;
use crate::maps::MapCache;
use crate::queue::PlanQueue;

/// Largest cancel decoded, bytes: an id and a token.
pub(super) const MAX_CANCEL_BYTES: usize = 4 * 1024;

/// Largest plan request accepted, in bytes.
pub const MAX_REQUEST_BYTES: usize = 64 * 1024;
/// The query parameter that names the client for its fair share of the queue
/// (`<root>/planner/plan?client=<name>`; [`crate::queue::ClientId`]).
pub const CLIENT_PARAMETER: &str = "client";

/// How often progress is published at most.
pub const PROGRESS_PERIOD: Duration = Duration::from_millis(50);

/// This planner instance, shared by its queryables and subscribers: its maps, its queue
/// and the plans it has in flight, its limits and its CPU budget.
pub(super) struct PlannerInstance {
    pub(super) root: String,
    pub(super) instance: String,
    pub(super) session: zenoh::Session,
    pub(super) maps: Mutex<MapCache>,
    /// Plans running and queued (`max_concurrent_plans`, `max_queued_plans`).
    pub(super) queue: PlanQueue,
    /// Plan requests received so far: each one's number is its place in the queue.
    pub(super) arrivals: AtomicU64,
    pub(super) plans: InFlight,
    pub(super) limits: PlanLimits,
    pub(super) budget: CpuBudget,
    /// Refused and unknown cancels, logged a few per window (`roam_runtime::warn_limit`).
    pub(super) cancel_warnings: WarnLimiter,
    /// Layers to get whole (a delta did not apply to the version held), and the wake-up
    /// of the task that gets them: a burst of such deltas costs one `get` per layer.
    pub(super) wanted: Mutex<BTreeSet<String>>,
    pub(super) want: tokio::sync::Notify,
    /// Deltas ignored (a body naming another layer than its key), logged a few per
    /// window.
    pub(super) delta_warnings: WarnLimiter,
}

impl PlannerInstance {
    pub(super) fn maps(&self) -> MutexGuard<'_, MapCache> {
        roam_runtime::lock(&self.maps)
    }
}

/// Removes a request from the table of plans in flight however it ends.
pub(super) struct Registration<'a> {
    pub(super) plans: &'a InFlight,
    /// The plan's cancel key, which it is registered under.
    pub(super) key: String,
}

impl Drop for Registration<'_> {
    fn drop(&mut self) {
        self.plans.remove(&self.key);
    }
}
