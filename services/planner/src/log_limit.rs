//! A rate limit for log lines that strangers can trigger (refused cancels): at most a
//! few lines per period, the rest counted and reported with the next line let through,
//! so a flood of bad cancels costs a counter increment each, not a log line each.

use std::sync::Mutex;
use std::time::{Duration, Instant};

#[derive(Debug)]
struct Window {
    started: Option<Instant>,
    logged: u32,
    suppressed: u64,
}

/// Lets through at most `burst` lines per `period`.
#[derive(Debug)]
pub struct LogLimit {
    burst: u32,
    period: Duration,
    window: Mutex<Window>,
}

impl LogLimit {
    pub const fn new(burst: u32, period: Duration) -> Self {
        LogLimit {
            burst,
            period,
            window: Mutex::new(Window {
                started: None,
                logged: 0,
                suppressed: 0,
            }),
        }
    }

    /// `Some(n)` when a line may be logged at `now`, `n` the lines suppressed since the
    /// last one let through; `None` when this one is suppressed (and counted).
    pub fn admit(&self, now: Instant) -> Option<u64> {
        let mut w = self.window.lock().unwrap_or_else(|p| p.into_inner());
        let expired = w
            .started
            .is_none_or(|s| now.saturating_duration_since(s) >= self.period);
        if expired {
            w.started = Some(now);
            w.logged = 0;
        }
        if w.logged < self.burst {
            w.logged += 1;
            Some(std::mem::take(&mut w.suppressed))
        } else {
            w.suppressed += 1;
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flood_is_cut_to_the_burst_and_counted() {
        let limit = LogLimit::new(3, Duration::from_secs(1));
        let t0 = Instant::now();
        let admitted: Vec<Option<u64>> = (0..1000).map(|_| limit.admit(t0)).collect();
        assert_eq!(admitted.iter().filter(|a| a.is_some()).count(), 3);
        assert_eq!(&admitted[..3], &[Some(0), Some(0), Some(0)]);
        // The next period lets lines through again and reports what was dropped.
        assert_eq!(limit.admit(t0 + Duration::from_secs(1)), Some(997));
        assert_eq!(limit.admit(t0 + Duration::from_millis(1500)), Some(0));
    }
}
