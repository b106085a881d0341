//! The arrival margin: what a window's plan leaves unspent of the time to its task, sized
//! so that the plan arrives late with at most a configured probability.
//!
//! A curious plan fills its budget to the second (round trips and via-point seeds make
//! sure of it), so any error of the time model (paper 000 Eq. 2's v_lin and v_ang
//! against what the robot really needs) makes the robot late unless the budget leaves
//! room for it. The room comes from what this robot's own model got wrong: every
//! arrived drive gives a relative error `e = took / predicted − 1`, and the margin
//! treats the next drive's error as drawn from the same distribution.
//!
//! **The rule (roam's; the papers have no arrival margin).** The errors are taken as
//! normal, `e ~ N(μ, σ²)`, estimated with a prior of [`PRIOR_PSEUDO_DRIVES`] drives at
//! mean 0 and spread [`PRIOR_SIGMA`] (before anything was driven, Table I is trusted to
//! 10%), over the last [`MAX_ERRORS`] drives:
//!
//! ```text
//! μ = Σe / (k₀ + n)        σ² = (k₀·σ₀² + Σ(e − μ)²) / (k₀ + n)
//! q = μ + z_(1−p) · σ · √(1 + 1/(k₀ + n))        (the predictive quantile)
//! budget = (T − min_s) / (1 + max(q, share))
//! ```
//!
//! with `T` the time left to the task, `p` the late probability asked for (default
//! 10⁻³, z = 3.09), `share` a floor share and `min_s` seconds kept back on top of the
//! relative margin: what a drive loses whatever its length (setting off and turning
//! toward the path, the controller's goal tolerance, a sim step). Measured in 20 batch
//! days, a drive's excess over its prediction was up to 1.6 s on drives predicted at 1
//! to 6 s (a relative error of up to +200%), which no share of a short drive covers:
//! the two parts add. `q` is capped at
//! [`MAX_SHARE`] so that a wildly wrong model still leaves a budget; the probability a
//! plan actually has is reported with it ([`ArrivalMargin::late_probability`]). A drive
//! the model overestimated (e < 0) narrows the margin, and the slack rule
//! ([`crate::watch`]) gives back what the robot did not need as a curious replan.

/// The margin's largest share of a drive's predicted time, whatever the model's error.
pub const MAX_SHARE: f64 = 0.5;
/// Drives the error distribution remembers (the most recent).
pub const MAX_ERRORS: usize = 64;
/// The prior's spread of the relative error before anything was driven.
pub const PRIOR_SIGMA: f64 = 0.10;
/// How many drives the prior counts as.
pub const PRIOR_PSEUDO_DRIVES: f64 = 2.0;

/// The margin's rule and the errors it has seen.
#[derive(Debug, Clone, PartialEq)]
pub struct ArrivalMargin {
    share: f64,
    min_s: f64,
    late_probability: f64,
    /// The recent relative errors, oldest first.
    errors: Vec<f64>,
}

impl ArrivalMargin {
    /// At least `share` of the drive and `min_s` seconds, sized for `late_probability`
    /// (all three checked by the executive's config).
    pub fn new(share: f64, min_s: f64, late_probability: f64) -> ArrivalMargin {
        ArrivalMargin {
            share,
            min_s,
            late_probability,
            errors: Vec::new(),
        }
    }

    /// No margin at all: the plan may use all the time left.
    pub fn none() -> ArrivalMargin {
        ArrivalMargin::new(0.0, 0.0, 1.0)
    }

    /// The error distribution's mean and predictive spread (module doc).
    fn distribution(&self) -> (f64, f64) {
        let n = self.errors.len() as f64;
        let k = PRIOR_PSEUDO_DRIVES + n;
        let mean = self.errors.iter().sum::<f64>() / k;
        let spread: f64 = self.errors.iter().map(|e| (e - mean).powi(2)).sum();
        let sigma = ((PRIOR_PSEUDO_DRIVES * PRIOR_SIGMA * PRIOR_SIGMA + spread) / k).sqrt();
        (mean, sigma * (1.0 + 1.0 / k).sqrt())
    }

    /// The relative error the margin allows for: the quantile `1 − late_probability`
    /// of the errors, at least the floor share, at most [`MAX_SHARE`].
    pub fn allowance(&self) -> f64 {
        if self.late_probability >= 1.0 {
            return self.share;
        }
        let (mean, sigma) = self.distribution();
        let q = mean + normal_quantile(1.0 - self.late_probability) * sigma;
        q.max(self.share).min(MAX_SHARE)
    }

    /// The driving budget for `time_left_s` seconds to the task (negative when not
    /// even the seconds kept back fit).
    pub fn budget(&self, time_left_s: f64) -> f64 {
        let after_floor = time_left_s - self.min_s;
        if after_floor <= 0.0 {
            return after_floor;
        }
        after_floor / (1.0 + self.allowance())
    }

    /// The probability that a drive predicted at `predicted_s` takes longer than
    /// `time_left_s`, under the error distribution (1 when nothing fits).
    pub fn late_probability(&self, predicted_s: f64, time_left_s: f64) -> f64 {
        if predicted_s <= 0.0 {
            return if time_left_s >= 0.0 { 0.0 } else { 1.0 };
        }
        let (mean, sigma) = self.distribution();
        let room = time_left_s / predicted_s - 1.0;
        1.0 - normal_cdf((room - mean) / sigma)
    }

    /// A drive the model predicted at `predicted_s` took `took_s`.
    pub fn learn(&mut self, predicted_s: f64, took_s: f64) {
        if predicted_s > 0.0 && took_s.is_finite() && took_s >= 0.0 {
            if self.errors.len() == MAX_ERRORS {
                self.errors.remove(0);
            }
            self.errors.push(took_s / predicted_s - 1.0);
        }
    }

    /// The drives learnt from so far (at most [`MAX_ERRORS`]).
    pub fn drives(&self) -> usize {
        self.errors.len()
    }
}

/// Φ, the standard normal CDF (Abramowitz & Stegun 7.1.26 through erf; absolute error
/// below 1.5·10⁻⁷, ample for a margin).
pub fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-z * z).exp();
    if x >= 0.0 {
        0.5 * (1.0 + erf)
    } else {
        0.5 * (1.0 - erf)
    }
}

/// Φ⁻¹(p) for p in (0, 1) (Acklam's rational approximation, relative error below
/// 1.2·10⁻⁹); ±∞ at the ends.
pub fn normal_quantile(p: f64) -> f64 {
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    let low = 0.02425;
    if p < low {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - low {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A normal draw (Box–Muller on two uniforms).
    fn normal(rng: &mut ChaCha8Rng, mean: f64, sd: f64) -> f64 {
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        mean + sd * (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    #[test]
    fn the_normal_functions_invert_each_other() {
        for p in [1e-6, 1e-3, 0.02, 0.3, 0.5, 0.9, 0.999] {
            let x = normal_quantile(p);
            assert!((normal_cdf(x) - p).abs() < 2e-7, "p {p}: x {x}");
        }
        assert!((normal_quantile(0.999) - 3.090_232).abs() < 1e-5);
    }

    #[test]
    fn no_margin_spends_everything_and_the_floors_hold() {
        assert_eq!(ArrivalMargin::none().budget(70.0), 70.0);
        // Before any drive: the prior alone, 10% spread at p = 1e-3 (q ≈ 0.38).
        let m = ArrivalMargin::new(0.05, 2.0, 1e-3);
        let q = m.allowance();
        assert!((0.3..0.45).contains(&q), "{q}");
        assert!((m.budget(100.0) - 98.0 / (1.0 + q)).abs() < 1e-9);
        assert!(
            (m.budget(3.0) - 1.0 / (1.0 + q)).abs() < 1e-12,
            "the 2 s floor, then the share"
        );
        assert!(
            (m.budget(1.5) + 0.5).abs() < 1e-12,
            "not even the floor fits"
        );
    }

    #[test]
    fn an_accurate_model_narrows_the_margin_and_a_biased_one_widens_it() {
        let mut accurate = ArrivalMargin::new(0.02, 0.0, 1e-3);
        let mut slow = ArrivalMargin::new(0.02, 0.0, 1e-3);
        for i in 0..40 {
            let wobble = if i % 2 == 0 { 0.01 } else { -0.01 };
            accurate.learn(100.0, 100.0 * (1.0 + wobble));
            slow.learn(100.0, 100.0 * (1.2 + wobble));
        }
        // The prior (10% spread over two drives) still counts after 40 drives of ±1%.
        assert!(accurate.allowance() < 0.08, "{}", accurate.allowance());
        assert!(slow.allowance() > 0.2, "{}", slow.allowance());
        assert_eq!(accurate.drives(), 40);
        let after_forty = accurate.allowance();
        for _ in 0..100 {
            accurate.learn(10.0, 10.0);
        }
        assert_eq!(accurate.drives(), MAX_ERRORS, "bounded");
        assert!(
            accurate.allowance() < after_forty,
            "more exact drives, a narrower margin"
        );
        let before = accurate.clone();
        accurate.learn(0.0, 5.0);
        accurate.learn(5.0, f64::NAN);
        assert_eq!(accurate, before, "nonsense is ignored");
    }

    /// A time model with a known error (the robot takes 1.04× to 1.10× what it is
    /// predicted, normally spread): over many seeded windows the margin learns it, and
    /// the share of late arrivals stays within the bound it was sized for.
    #[test]
    fn the_observed_late_share_stays_within_its_bound() {
        for (seed, bias, spread) in [(1u64, 0.04, 0.03), (2, 0.10, 0.05), (3, -0.05, 0.08)] {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let p = 1e-3;
            let mut margin = ArrivalMargin::new(0.0, 0.0, p);
            let (mut late, mut bound_sum, windows) = (0u32, 0.0, 20_000);
            for _ in 0..windows {
                let time_left = rng.random_range(30.0..200.0);
                let predicted = margin.budget(time_left);
                bound_sum += margin.late_probability(predicted, time_left);
                let took = predicted * (1.0 + normal(&mut rng, bias, spread));
                if took > time_left {
                    late += 1;
                }
                margin.learn(predicted, took);
            }
            let observed = f64::from(late) / f64::from(windows);
            let bound = bound_sum / f64::from(windows);
            // Every plan was sized for p; the reported bound averages near it, and the
            // observed share (20,000 windows: a few late ones expected) is within it
            // up to sampling noise (3 standard errors of a binomial at 2p).
            assert!(bound <= 2.0 * p, "seed {seed}: mean bound {bound}");
            let noise = 3.0 * (2.0 * p / f64::from(windows)).sqrt();
            assert!(
                observed <= 2.0 * p + noise,
                "seed {seed}: {late} late of {windows} ({observed}) against p {p}"
            );
        }
    }
}
