//! The arrival margin: what a window's plan leaves unspent of the time to its task.
//!
//! A curious plan fills its budget to the second (round trips and via-point seeds make
//! sure of it), so any error of the time model (paper 000 Eq. 2's v_lin and v_ang
//! against what the robot really needs) or a slow stretch makes the robot late. The
//! margin absorbs it: a configured share of the time left, or the share by which the
//! robot's recent drives took longer than their model predicted if that is more (it
//! forgets by half each drive), at most [`MAX_SHARE`], and never less than a floor in
//! seconds. What the robot does not need, the slack rule ([`crate::watch`]) gives back
//! as a curious replan. The executive and the batch of days (`crate::days`) both plan
//! with this one rule.

/// The margin's largest share of the time to a task, whatever the model's error.
pub const MAX_SHARE: f64 = 0.25;
/// How much of the last underestimate the next drive still remembers.
const MEMORY: f64 = 0.5;

/// The margin's rule and what it has learnt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArrivalMargin {
    share: f64,
    min_s: f64,
    /// How much longer than predicted the recent drives took, as a share (0 when the
    /// model was right or pessimistic).
    underestimate: f64,
}

impl ArrivalMargin {
    /// `share` of the time left, at least `min_s` seconds (both checked by the
    /// executive's config).
    pub fn new(share: f64, min_s: f64) -> ArrivalMargin {
        ArrivalMargin {
            share,
            min_s,
            underestimate: 0.0,
        }
    }

    /// No margin at all: the plan may use all the time left (today's executive).
    pub fn none() -> ArrivalMargin {
        ArrivalMargin::new(0.0, 0.0)
    }

    /// The planning budget for `time_left_s` seconds to the task.
    pub fn budget(&self, time_left_s: f64) -> f64 {
        let share = self.share.max(self.underestimate).min(MAX_SHARE);
        time_left_s - (time_left_s * share).max(self.min_s)
    }

    /// A drive the model predicted at `predicted_s` took `took_s`.
    pub fn learn(&mut self, predicted_s: f64, took_s: f64) {
        if predicted_s > 0.0 && took_s.is_finite() {
            let error = (took_s / predicted_s - 1.0).max(0.0);
            self.underestimate = error.max(MEMORY * self.underestimate);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_margin_is_a_share_with_a_floor() {
        let m = ArrivalMargin::new(0.05, 2.0);
        assert!((m.budget(100.0) - 95.0).abs() < 1e-12);
        assert!((m.budget(20.0) - 18.0).abs() < 1e-12, "the 2 s floor");
        assert_eq!(ArrivalMargin::none().budget(70.0), 70.0);
    }

    #[test]
    fn an_underestimating_model_widens_the_margin_then_it_is_forgotten() {
        let mut m = ArrivalMargin::new(0.05, 0.0);
        // 60 s predicted, 72 s taken: 20% under.
        m.learn(60.0, 72.0);
        assert!((m.budget(100.0) - 80.0).abs() < 1e-9);
        // A pessimistic drive halves what is remembered.
        m.learn(60.0, 50.0);
        assert!((m.budget(100.0) - 90.0).abs() < 1e-9);
        // Never more than MAX_SHARE.
        m.learn(10.0, 100.0);
        assert!((m.budget(100.0) - 100.0 * (1.0 - MAX_SHARE)).abs() < 1e-9);
        // Nonsense is ignored.
        let before = m;
        m.learn(0.0, 5.0);
        m.learn(5.0, f64::NAN);
        assert_eq!(m, before);
    }
}
