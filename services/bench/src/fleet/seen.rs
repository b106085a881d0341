//! What the bench's subscribers saw, and the timed run's on-time count read off it.

use std::collections::{BTreeMap, HashMap};
use std::time::Instant;

/// What the subscribers saw.
#[derive(Debug, Default)]
pub(super) struct Seen {
    /// The latest clock step, and when each clock arrived.
    pub(super) clocks: Vec<(u64, Instant)>,
    /// Per robot, the first step it had a command for and when that command arrived.
    pub(super) first: HashMap<String, (u64, Instant)>,
    pub(super) on_time: u64,
    pub(super) late: u64,
    /// Per step, the commands for it that were on time.
    pub(super) on_time_at: BTreeMap<u64, u64>,
    /// From this instant on (the router's restart), per robot, when its first command
    /// arrived.
    pub(super) since: Option<Instant>,
    pub(super) again: HashMap<String, Instant>,
}

/// The timed run's figures of the loop (before the restart phase adds to what was seen).
pub(super) struct Steady {
    pub(super) expected: u64,
    pub(super) on_time: u64,
    pub(super) late: u64,
    pub(super) periods: Vec<f64>,
}

/// The timed run's commands as seen so far.
pub(super) fn steady(seen: &Seen, robots: usize) -> Steady {
    let last = seen.clocks.iter().map(|c| c.0).max().unwrap_or(0);
    // Every robot should have had a command for each step from its first to the last.
    let expected: u64 = seen
        .first
        .values()
        .map(|&(first, _)| last.saturating_sub(first) + 1)
        .sum::<u64>()
        + (robots.saturating_sub(seen.first.len()) as u64) * last;
    let mut periods: Vec<f64> = seen
        .clocks
        .windows(2)
        .filter(|w| w[1].0 == w[0].0 + 1)
        .map(|w| (w[1].1 - w[0].1).as_secs_f64() * 1000.0)
        .collect();
    periods.sort_by(f64::total_cmp);
    Steady {
        expected,
        on_time: seen.on_time,
        late: seen.late,
        periods,
    }
}

/// `part` over `whole`, 0 when there is no whole.
pub(super) fn share(part: u64, whole: u64) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 / whole as f64
    }
}
