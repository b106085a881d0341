//! Stepping on its own at a real-time factor, until paused.

use std::sync::Arc;
use std::time::Duration;

use tokio::time::Instant;
use tokio_util::sync::CancellationToken;

use super::shared::SimShared;
use super::step::{publish, step_once};

/// Wall time between free-running steps at `rate` (0: none). The rate was checked, so
/// the period is at most `step_s / MIN_RATE`; a step_s the scenario check let through
/// cannot make it panic either.
fn step_period(step_s: f64, rate: f64) -> Duration {
    if rate > 0.0 {
        Duration::try_from_secs_f64(step_s / rate).unwrap_or(Duration::from_secs(60))
    } else {
        Duration::ZERO
    }
}

/// Steps while running: every `step_s / rate` seconds of wall time, or back to back at
/// rate 0. A step whose messages are not out before the next one is due counts as late.
/// Every control request wakes it ([`SimShared::wake`]), so a pause, a reset or a new rate
/// takes effect at once, whatever the period was.
pub(super) async fn free_run(state: Arc<SimShared>, cancel: CancellationToken) {
    let mut next = Instant::now();
    loop {
        let (running, period) = {
            let c = state.control();
            (c.running, step_period(c.sim.params().time.step_s, c.rate))
        };
        if !running {
            tokio::select! {
                _ = cancel.cancelled() => return,
                _ = state.wake.notified() => {}
                _ = tokio::time::sleep(Duration::from_millis(100)) => {}
            }
            next = Instant::now();
            continue;
        }
        {
            let _stepping = state.stepper.lock().await;
            if !state.control().running {
                continue;
            }
            match step_once(&state) {
                Ok(stepped) => publish(&state, stepped).await,
                Err(e) => tracing::warn!("step failed: {e}"),
            }
        }
        next += period;
        let now = Instant::now();
        {
            let mut c = state.control();
            c.free_steps += 1;
            if now > next {
                c.late_steps += 1;
            }
        }
        if now > next + period * 4 {
            // Far behind (a pause of the machine): catch up from now, not in a burst.
            next = now;
        }
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = state.wake.notified() => next = Instant::now(),
            _ = tokio::time::sleep_until(next) => {}
            _ = tokio::task::yield_now(), if period.is_zero() => {}
        }
    }
}
