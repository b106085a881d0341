//! Message times against the sim clock, and sim resets as new epochs: the one check of
//! a stamped message's time (an observation for the mapper, a range scan for
//! localization) every service makes the same way.
//!
//! A time from the wire is not to be believed as it comes: paper 004's change map needs
//! time to run forward (each cell's Poisson processes are rates per second since the
//! cell was first seen, and the map refuses a window older than its latest), and an
//! estimate carries its scan's time to the controller and the executive. One message
//! stamped `time_s: 1e300`, taken as it came, made every later one look like time going
//! back; a sim `reset` (time back to 0) looked the same.
//!
//! [`Epochs`] follows the sim clock (`<root>/sim/clock`). A message is taken only when
//! its time is at most [`MAX_CLOCK_SKEW_S`] ahead of the clock. One behind the clock is
//! taken: it waited in its subscriber's queue while the clock's subscriber went on (a
//! busy localization runs a few steps behind the sim), and a time in the past cannot
//! push a service's time forward. When the clock goes back (a reset or a load), a new
//! epoch begins: service time continues from where it was (`service time = sim time +
//! offset`), so a history is kept and never sees time run backwards. Messages in flight
//! across the reset that are stamped in the old epoch are ahead of the new clock and
//! refused; those stamped in the new one before its first clock get the old epoch's
//! offset, which puts them behind what the service has seen (the change map refuses
//! such a window): at most a step's worth.
//!
//! Without a sim clock (a real robot's messages, wall time), times are taken as they
//! come but a jump more than [`MAX_JUMP_S`] past the latest one is refused, so one bad
//! stamp cannot stop the service.

use roam_proto::number;

/// How far a message's time may be ahead of the sim clock, seconds.
pub const MAX_CLOCK_SKEW_S: f64 = 5.0;

/// Without a sim clock: how far past the latest message time one may jump, seconds.
pub const MAX_JUMP_S: f64 = 3600.0;

/// Without a sim clock: the latest time a first message may carry, seconds (about
/// 32 years of sim or robot uptime; not a calendar date).
pub const MAX_TIME_S: f64 = 1e9;

/// The clock a service checks message times against.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Epochs {
    /// The latest sim clock time heard, seconds.
    clock_s: Option<f64>,
    /// Added to sim time to make service time.
    offset_s: f64,
    /// Resets seen.
    epoch: u64,
    /// The latest accepted message time (service time).
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

    /// The service time of a message stamped `time_s` (sim or robot time), or why it is
    /// refused. The reason quotes times as [`number`]s: a 1e300 from the wire is not
    /// logged as 301 digits.
    pub fn observation_time(&mut self, time_s: f64) -> Result<f64, String> {
        if !time_s.is_finite() || time_s < 0.0 {
            return Err(format!("its time {} s is not a time", number(time_s)));
        }
        let mapped = match self.clock_s {
            Some(clock) => {
                if time_s - clock > MAX_CLOCK_SKEW_S {
                    return Err(format!(
                        "its time {} s is ahead of the sim clock ({} s) by more than {MAX_CLOCK_SKEW_S} s",
                        number(time_s),
                        number(clock)
                    ));
                }
                time_s + self.offset_s
            }
            None => {
                let limit = self.latest_s.map_or(MAX_TIME_S, |t| t + MAX_JUMP_S);
                if time_s > limit {
                    return Err(format!(
                        "its time {} s jumps past {} s (no sim clock: at most {MAX_JUMP_S} s past the latest message)",
                        number(time_s),
                        number(limit)
                    ));
                }
                time_s
            }
        };
        Ok(mapped)
    }

    /// Records that a message at service time `mapped_s` was taken.
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
    fn a_huge_time_is_quoted_briefly() {
        let mut e = Epochs::default();
        e.on_clock(10.0);
        let refused = e.observation_time(1e300).expect_err("off the clock");
        assert!(refused.contains("1e300"), "{refused}");
        assert!(refused.len() < 120, "{refused}");
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
        // A stale observation of the old epoch is ahead of the new clock.
        assert!(e.observation_time(499.0).is_err());
    }

    #[test]
    fn a_message_behind_the_clock_waited_in_its_queue_and_is_taken() {
        let mut e = Epochs::default();
        e.on_clock(40.0);
        assert_eq!(e.observation_time(20.0), Ok(20.0));
        assert_eq!(e.observation_time(44.0), Ok(44.0));
        assert!(e.observation_time(45.5).is_err());
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
