//! The instance's CPU budget across clients: how much wall time its plans may take.
//!
//! The unit is the *plan-second*: one plan planning for one wall-clock second (on up to
//! [`crate::ga::default_threads`] evaluation threads). The budget is a token bucket:
//! it holds at most `plan_seconds_burst` plan-seconds and refills at
//! `plan_seconds_per_second`. Before a plan starts it is granted, up front,
//! `min(deadline_s, max_plan_seconds, what the bucket holds)` seconds, and that is its
//! wall deadline; when it ends, what it did not use goes back to the bucket. A plan is
//! refused `busy` (limit `plan_seconds_burst`) only when the bucket holds less than
//! [`MIN_GRANT_S`] (or the plan's whole deadline, if shorter).
//!
//! So one plan takes at most `max_plan_seconds`, and over any long stretch an instance
//! plans at most `plan_seconds_per_second` plan-seconds per second, whoever asks: two
//! huge requests are cut at `max_plan_seconds` each, and a client that keeps sending
//! them gets what the bucket refills, not both cores.
//!
//! A grant only moves the plan's wall deadline. A plan that ends by its generation
//! count before its grant runs out is the same bit for bit whatever the bucket held;
//! one that runs into a grant shorter than its own deadline says so in its reply
//! (`stop_reason: cpu_grant`, with the seconds granted in `cpu_grant_s`), since a GA is anytime and returns
//! its best path so far.

use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The smallest grant worth starting a plan for, seconds (a plan whose own deadline is
/// shorter needs only that).
pub const MIN_GRANT_S: f64 = 1.0;

/// The budget's three numbers (see the module doc and [`crate::PlannerConfig`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BudgetConfig {
    pub max_plan_seconds: f64,
    pub plan_seconds_per_second: f64,
    pub plan_seconds_burst: f64,
}

impl Default for BudgetConfig {
    fn default() -> Self {
        BudgetConfig {
            max_plan_seconds: 30.0,
            plan_seconds_per_second: 0.5,
            plan_seconds_burst: 60.0,
        }
    }
}

impl BudgetConfig {
    /// Every number must be positive and finite; names the first that is not.
    pub fn validate(&self) -> Result<(), String> {
        for (name, value) in [
            ("max_plan_seconds", self.max_plan_seconds),
            ("plan_seconds_per_second", self.plan_seconds_per_second),
            ("plan_seconds_burst", self.plan_seconds_burst),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(format!(
                    "{name} = {value}; use a positive number of seconds"
                ));
            }
        }
        Ok(())
    }
}

#[derive(Debug)]
struct Bucket {
    /// Plan-seconds held; below 0 when plans overran their grants (a generation ends
    /// after the deadline), which later grants pay back.
    tokens: f64,
    at: Instant,
}

/// The bucket of plan-seconds of one instance.
#[derive(Debug)]
pub struct CpuBudget {
    config: BudgetConfig,
    bucket: Mutex<Bucket>,
}

/// The bucket held too little for a plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exhausted {
    /// Plan-seconds the bucket held.
    pub available_s: f64,
    /// What the plan needed at least.
    pub needed_s: f64,
    /// Seconds until the bucket holds that much.
    pub retry_in_s: f64,
}

/// Wall time granted to one plan; what it does not use returns to the bucket when the
/// grant is dropped (or [`Grant::finish`]ed).
#[derive(Debug)]
pub struct Grant<'a> {
    budget: &'a CpuBudget,
    /// The plan's wall deadline, seconds from `started`.
    pub seconds: f64,
    /// Whether the grant is shorter than the deadline the request asked for.
    pub cut: bool,
    started: Instant,
    settled: bool,
}

impl CpuBudget {
    /// A full bucket at `now`.
    pub fn new(config: BudgetConfig, now: Instant) -> Self {
        CpuBudget {
            config,
            bucket: Mutex::new(Bucket {
                tokens: config.plan_seconds_burst,
                at: now,
            }),
        }
    }

    pub fn config(&self) -> BudgetConfig {
        self.config
    }

    fn refilled(&self, now: Instant) -> std::sync::MutexGuard<'_, Bucket> {
        let mut bucket = roam_runtime::lock(&self.bucket);
        let elapsed = now.saturating_duration_since(bucket.at).as_secs_f64();
        bucket.tokens = (bucket.tokens + elapsed * self.config.plan_seconds_per_second)
            .min(self.config.plan_seconds_burst);
        bucket.at = bucket.at.max(now);
        bucket
    }

    /// Plan-seconds the bucket holds at `now`.
    pub fn available(&self, now: Instant) -> f64 {
        self.refilled(now).tokens
    }

    /// Grants a plan that asks for `deadline_s` (positive and finite, checked before)
    /// its wall time at `now`: see the module doc.
    pub fn grant(&self, deadline_s: f64, now: Instant) -> Result<Grant<'_>, Exhausted> {
        let want = deadline_s.min(self.config.max_plan_seconds);
        let needed = want.min(MIN_GRANT_S);
        let mut bucket = self.refilled(now);
        if bucket.tokens < needed {
            return Err(Exhausted {
                available_s: bucket.tokens,
                needed_s: needed,
                retry_in_s: (needed - bucket.tokens) / self.config.plan_seconds_per_second,
            });
        }
        let seconds = want.min(bucket.tokens);
        bucket.tokens -= seconds;
        Ok(Grant {
            budget: self,
            seconds,
            cut: seconds < deadline_s,
            started: now,
            settled: false,
        })
    }

    fn settle(&self, granted: f64, used: f64, now: Instant) {
        let mut bucket = self.refilled(now);
        let burst = self.config.plan_seconds_burst;
        bucket.tokens = (bucket.tokens + granted - used).clamp(-burst, burst);
    }
}

impl Grant<'_> {
    /// The wall deadline as a duration.
    pub fn duration(&self) -> Duration {
        Duration::from_secs_f64(self.seconds)
    }

    /// Ends the grant at `now`: the plan used `now - start` plan-seconds, and the rest
    /// of the grant returns to the bucket (an overrun is taken from it).
    pub fn finish(mut self, now: Instant) {
        self.settle(now);
    }

    fn settle(&mut self, now: Instant) {
        if !self.settled {
            self.settled = true;
            let used = now.saturating_duration_since(self.started).as_secs_f64();
            self.budget.settle(self.seconds, used, now);
        }
    }
}

impl Drop for Grant<'_> {
    fn drop(&mut self) {
        self.settle(Instant::now());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn budget(t0: Instant) -> CpuBudget {
        CpuBudget::new(
            BudgetConfig {
                max_plan_seconds: 30.0,
                plan_seconds_per_second: 0.5,
                plan_seconds_burst: 60.0,
            },
            t0,
        )
    }

    fn at(t0: Instant, s: f64) -> Instant {
        t0 + Duration::from_secs_f64(s)
    }

    #[test]
    fn a_plan_gets_its_deadline_up_to_max_plan_seconds() {
        let t0 = Instant::now();
        let b = budget(t0);
        let g = b.grant(5.0, t0).expect("granted");
        assert_eq!((g.seconds, g.cut), (5.0, false));
        g.finish(at(t0, 1.0));
        // 55 after the grant, 0.5 refilled in 1 s, 4 of the 5 s returned.
        assert!((b.available(at(t0, 1.0)) - 59.5).abs() < 1e-9);
        let g = b.grant(600.0, at(t0, 1.0)).expect("granted");
        assert_eq!((g.seconds, g.cut), (30.0, true));
    }

    #[test]
    fn two_huge_plans_drain_the_bucket_and_a_third_is_refused_until_it_refills() {
        let t0 = Instant::now();
        let b = budget(t0);
        let first = b.grant(600.0, t0).expect("first");
        let second = b.grant(600.0, t0).expect("second");
        assert_eq!((first.seconds, second.seconds), (30.0, 30.0));
        let refused = b.grant(600.0, t0).expect_err("empty");
        assert_eq!(refused.needed_s, MIN_GRANT_S);
        assert!((refused.retry_in_s - 2.0).abs() < 1e-9, "{refused:?}");
        // Both use their 30 s; meanwhile 15 plan-seconds came back.
        first.finish(at(t0, 30.0));
        second.finish(at(t0, 30.0));
        assert!((b.available(at(t0, 30.0)) - 15.0).abs() < 1e-9);
        // The next huge plan gets what is there, and is told it was cut.
        let third = b.grant(600.0, at(t0, 30.0)).expect("third");
        assert!((third.seconds - 15.0).abs() < 1e-9 && third.cut);
        // A short plan asks only for its own deadline.
        assert!(b.grant(0.5, at(t0, 30.0)).is_err());
        assert!(b.grant(0.5, at(t0, 31.0)).is_ok());
    }

    #[test]
    fn unused_time_returns_and_overruns_are_paid_back() {
        let t0 = Instant::now();
        let b = budget(t0);
        let g = b.grant(30.0, t0).expect("granted");
        drop(b.grant(30.0, t0).expect("granted")); // used ~0 s: all back
        assert!(b.available(t0) > 29.9);
        g.finish(at(t0, 31.0)); // overran by 1 s
                                // 60 - 31 used + 15.5 refilled over 31 s (less the instant the other plan took).
        assert!((b.available(at(t0, 31.0)) - 44.5).abs() < 1e-2);
    }

    #[test]
    fn every_number_must_be_positive() {
        assert!(BudgetConfig::default().validate().is_ok());
        let bad = BudgetConfig {
            plan_seconds_per_second: 0.0,
            ..BudgetConfig::default()
        };
        assert!(bad
            .validate()
            .expect_err("refused")
            .contains("plan_seconds_per_second"));
    }
}
