//! Rate-limited warnings: a peer that sends a thousand bad messages a second gets a few
//! log lines and a count, not a thousand lines.
//!
//! Each source (a key, a robot) may log [`BURST`] lines per [`WINDOW`]; what it sends
//! beyond that is counted, and the next line it may log says how many were suppressed.
//! At most [`MAX_SOURCES`] sources are tracked; when a stranger sends from more keys
//! than that, the others share one bucket, so the limiter itself never grows without
//! bound.

use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Lines one source may log per window.
pub const BURST: u32 = 5;
/// The window over which [`BURST`] applies.
pub const WINDOW: Duration = Duration::from_secs(10);
/// Sources tracked one by one; the rest share a bucket.
pub const MAX_SOURCES: usize = 256;

const OTHERS: &str = "<other sources>";

#[derive(Debug)]
struct Bucket {
    window_start: Instant,
    logged: u32,
    suppressed: u64,
}

/// A set of per-source budgets for warnings.
#[derive(Debug, Default)]
pub struct WarnLimiter {
    buckets: Mutex<HashMap<String, Bucket>>,
}

impl WarnLimiter {
    pub fn new() -> Self {
        WarnLimiter::default()
    }

    /// Whether `source` may log now: `Some(n)` with the number of lines suppressed since
    /// its last one (say it in the line when above 0), `None` to stay quiet.
    pub fn allow(&self, source: &str) -> Option<u64> {
        self.allow_at(source, Instant::now())
    }

    fn allow_at(&self, source: &str, now: Instant) -> Option<u64> {
        let mut buckets = crate::lock(&self.buckets);
        if !buckets.contains_key(source) && buckets.len() >= MAX_SOURCES {
            buckets.retain(|_, b| now.duration_since(b.window_start) < WINDOW);
        }
        let key = if buckets.contains_key(source) || buckets.len() < MAX_SOURCES {
            source
        } else {
            OTHERS
        };
        let bucket = buckets.entry(key.to_owned()).or_insert(Bucket {
            window_start: now,
            logged: 0,
            suppressed: 0,
        });
        if now.duration_since(bucket.window_start) >= WINDOW {
            bucket.window_start = now;
            bucket.logged = 0;
        }
        if bucket.logged < BURST {
            bucket.logged += 1;
            Some(std::mem::take(&mut bucket.suppressed))
        } else {
            bucket.suppressed += 1;
            None
        }
    }
}

/// Logs a warning about wire data through a [`WarnLimiter`]: at most [`BURST`] lines per
/// source per [`WINDOW`], each saying how many were suppressed before it. Everything in
/// the line that came from the wire must already be an
/// [`excerpt`](roam_proto::excerpt()).
#[macro_export]
macro_rules! limited_warn {
    ($limiter:expr, $source:expr, $($arg:tt)+) => {
        if let Some(suppressed) = $limiter.allow($source) {
            if suppressed > 0 {
                ::tracing::warn!(suppressed, $($arg)+);
            } else {
                ::tracing::warn!($($arg)+);
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_burst_then_silence_then_the_count() {
        let limiter = WarnLimiter::new();
        let t0 = Instant::now();
        for _ in 0..BURST {
            assert_eq!(limiter.allow_at("a", t0), Some(0));
        }
        for _ in 0..1000 {
            assert_eq!(limiter.allow_at("a", t0), None);
        }
        assert_eq!(limiter.allow_at("b", t0), Some(0), "sources are apart");
        assert_eq!(limiter.allow_at("a", t0 + WINDOW), Some(1000));
    }

    #[test]
    fn many_sources_share_a_bucket_and_the_map_stays_bounded() {
        let limiter = WarnLimiter::new();
        let t0 = Instant::now();
        let mut allowed = 0;
        for i in 0..100_000 {
            if limiter.allow_at(&format!("robot-{i}"), t0).is_some() {
                allowed += 1;
            }
        }
        let tracked = limiter.buckets.lock().expect("lock").len();
        assert!(tracked <= MAX_SOURCES + 1, "{tracked} sources tracked");
        assert_eq!(allowed, (MAX_SOURCES as u32 + BURST) as usize);
    }
}
