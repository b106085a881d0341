//! Observation times against the clock, and sim resets as new epochs.
//!
//! Paper 004's change map needs time to run forward: each cell's Poisson processes are
//! rates per second since the cell was first seen, and the map refuses a window older
//! than its latest. Two things broke that in a running stack: one observation stamped
//! `time_s: 1e300` was accepted and every later one refused as time going back, and a
//! sim `reset` (time back to 0) stalled the mapper until sim time passed the old
//! maximum.
//!
//! [`Epochs`] follows the sim clock (`<root>/sim/clock`). An observation is taken only
//! when its time is within [`MAX_CLOCK_SKEW_S`] of the clock. When the clock goes back
//! (a reset or a load), a new epoch begins: mapper time continues from where it was
//! (`mapper time = sim time + offset`), so the world's history is kept and no cell sees
//! time run backwards. Observations in flight across the reset (stamped in the old
//! epoch, or in the new one before its first clock) are refused as off the clock:
//! at most a step's worth.
//!
//! Without a sim clock (a real robot's observations, wall time), times are taken as they
//! come but a jump more than [`MAX_JUMP_S`] past the latest one is refused, so one bad
//! stamp cannot stop the mapper.

/// How far an observation's time may be from the sim clock, seconds.
pub const MAX_CLOCK_SKEW_S: f64 = 5.0;

/// Without a sim clock: how far past the latest observation time one may jump, seconds.
pub const MAX_JUMP_S: f64 = 3600.0;

/// Without a sim clock: the latest time a first observation may carry, seconds (about
/// 32 years of sim or robot uptime; not a calendar date).
pub const MAX_TIME_S: f64 = 1e9;

/// The clock the mapper checks observation times against.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Epochs {
    /// The latest sim clock time heard, seconds.
    clock_s: Option<f64>,
    /// Added to sim time to make mapper time.
    offset_s: f64,
    /// Resets seen.
    epoch: u64,
    /// The latest accepted observation time (mapper time).
    latest_s: Option<f64>,
}

impl Epochs {
    /// Takes a sim clock reading; a clock that went back starts a new epoch.
    pub fn on_clock(&mut self, time_s: f64) {
        if !time_s.is_finite() || time_s < 0.0 {
            return;
        }
        if let Some(last) = self.clock_s {
            if time_s + 1e-9 < last {
                self.offset_s += last - time_s;
                self.epoch += 1;
            }
        }
        self.clock_s = Some(time_s);
    }

    /// The mapper time of an observation stamped `time_s` (sim or robot time), or why it
    /// is refused.
    pub fn observation_time(&mut self, time_s: f64) -> Result<f64, String> {
        if !time_s.is_finite() || time_s < 0.0 {
            return Err(format!("its time {time_s} s is not a time"));
        }
        let mapped = match self.clock_s {
            Some(clock) => {
                if (time_s - clock).abs() > MAX_CLOCK_SKEW_S {
                    return Err(format!(
                        "its time {time_s} s is off the sim clock ({clock} s) by more than {MAX_CLOCK_SKEW_S} s"
                    ));
                }
                time_s + self.offset_s
            }
            None => {
                let limit = self.latest_s.map_or(MAX_TIME_S, |t| t + MAX_JUMP_S);
                if time_s > limit {
                    return Err(format!(
                        "its time {time_s} s jumps past {limit} s (no sim clock: at most {MAX_JUMP_S} s past the latest observation)"
                    ));
                }
                time_s
            }
        };
        Ok(mapped)
    }

    /// Records that an observation at mapper time `mapped_s` was taken.
    pub fn accepted(&mut self, mapped_s: f64) {
        self.latest_s = Some(self.latest_s.map_or(mapped_s, |t| t.max(mapped_s)));
    }

    /// Sim resets (clock going back) seen so far.
    pub fn epoch(&self) -> u64 {
        self.epoch
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_forged_far_future_time_is_refused_and_the_next_taken() {
        let mut e = Epochs::default();
        e.on_clock(10.0);
        assert!(e.observation_time(1e300).is_err());
        assert_eq!(e.observation_time(10.1), Ok(10.1));
    }

    #[test]
    fn a_reset_starts_an_epoch_and_time_runs_on() {
        let mut e = Epochs::default();
        e.on_clock(500.0);
        let before = e.observation_time(500.0).expect("on the clock");
        e.accepted(before);
        e.on_clock(0.1);
        assert_eq!(e.epoch(), 1);
        let after = e.observation_time(0.2).expect("the new epoch");
        assert!(after > before, "{after} <= {before}");
        assert!((after - 500.1).abs() < 1e-9, "{after}");
        // A stale observation of the old epoch is off the new clock.
        assert!(e.observation_time(499.0).is_err());
    }

    #[test]
    fn without_a_clock_a_jump_is_bounded() {
        let mut e = Epochs::default();
        assert!(e.observation_time(f64::NAN).is_err());
        assert!(e.observation_time(1e300).is_err());
        let t = e.observation_time(100.0).expect("plausible");
        e.accepted(t);
        assert!(e.observation_time(100.0 + MAX_JUMP_S + 1.0).is_err());
        assert!(e.observation_time(200.0).is_ok());
    }
}
