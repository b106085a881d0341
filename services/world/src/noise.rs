//! Every random number the sim draws: the seeded streams, a Gaussian sampler, and paper
//! 002's two noise models (TOA ranging, §2.1; transition noise, Eq. 1).

use crate::scenario::SensingSpec;
use rand::RngCore;

/// A ChaCha8 stream for one consumer (`"world"`, `"robot/<name>"`) of a sim seeded with
/// `seed` ([`crate::seed::stream`]): each consumer draws only from its own stream,
/// so adding a robot, or a robot taking a different path, never changes what another
/// robot or the world draws.
pub use crate::seed::stream;

/// A uniform number in [0, 1) with 53 random bits.
pub fn uniform(rng: &mut impl RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A standard normal number by Box–Muller (two draws, the cosine branch only).
///
/// Written out rather than taken from `rand_distr`: the sim's streams must stay the
/// same bit for bit across dependency upgrades, and a library is free to change its
/// sampling algorithm (rand_distr's `Normal` uses a ziggurat whose tables and draw
/// count are its own business). Every call consumes exactly two `u64`s, so the number
/// of draws per step is fixed and easy to reason about.
pub fn standard_normal(rng: &mut impl RngCore) -> f64 {
    // 1 - [0, 1) is (0, 1]: ln never sees 0.
    let u1 = 1.0 - uniform(rng);
    let u2 = uniform(rng);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Paper 002 §2.1's TOA ranging noise: `d̂ = d + n`, n ~ N(0, σ²) up to d0 and
/// N(0, σ²((d/d0)^K + 1)) beyond.
///
/// Choices where the paper is ambiguous:
/// - **K is the exponent** (§2.1 writes `(d/d0)²` and §4 sets K = 2; roam reads the 2 as
///   K, so K is a parameter, `sensing.k`).
/// - **The step at d0**: read literally, the variance jumps from σ² to 2σ² at d0; roam
///   keeps that literal reading rather than inventing a continuous one.
/// - **No clamping**: a measured range may come out negative very close to an anchor;
///   it is reported as drawn, so the noise stays zero-mean.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToaNoise {
    /// σ_TOA, metres.
    pub sigma_m: f64,
    /// d0, metres.
    pub d0_m: f64,
    /// K, the exponent.
    pub k: f64,
}

impl ToaNoise {
    pub fn from_spec(spec: &SensingSpec) -> ToaNoise {
        ToaNoise {
            sigma_m: spec.sigma_toa_m,
            d0_m: spec.d0_m,
            k: spec.k,
        }
    }

    /// The noise variance at true distance `d`, m².
    pub fn variance(&self, d: f64) -> f64 {
        let s2 = self.sigma_m * self.sigma_m;
        if d <= self.d0_m {
            s2
        } else {
            s2 * ((d / self.d0_m).powf(self.k) + 1.0)
        }
    }

    /// The noise standard deviation at true distance `d`, metres.
    pub fn sigma(&self, d: f64) -> f64 {
        self.variance(d).sqrt()
    }

    /// A measured range for true distance `d`: always one Gaussian draw.
    pub fn measure(&self, d: f64, rng: &mut impl RngCore) -> f64 {
        d + self.sigma(d) * standard_normal(rng)
    }
}

/// Paper 002 Eq. 1's transition noise ν ~ N(0, σ_tr²), independent per axis: always two
/// Gaussian draws, x then y.
pub fn transition(sigma_tr_m: f64, rng: &mut impl RngCore) -> [f64; 2] {
    let nx = standard_normal(rng);
    let ny = standard_normal(rng);
    [sigma_tr_m * nx, sigma_tr_m * ny]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_differ_by_label_and_repeat_by_seed() {
        let a = stream(7, "robot/a").next_u64();
        assert_eq!(a, stream(7, "robot/a").next_u64());
        assert_ne!(a, stream(7, "robot/b").next_u64());
        assert_ne!(a, stream(8, "robot/a").next_u64());
    }

    #[test]
    fn the_variance_follows_the_model() {
        let n = ToaNoise {
            sigma_m: 0.1,
            d0_m: 15.0,
            k: 2.0,
        };
        assert!((n.variance(5.0) - 0.01).abs() < 1e-15);
        assert!((n.variance(15.0) - 0.01).abs() < 1e-15);
        assert!((n.variance(30.0) - 0.05).abs() < 1e-15);
        let cubic = ToaNoise { k: 3.0, ..n };
        assert!((cubic.variance(30.0) - 0.09).abs() < 1e-15);
    }

    #[test]
    fn uniforms_stay_in_range() {
        let mut rng = stream(1, "t");
        for _ in 0..10_000 {
            let u = uniform(&mut rng);
            assert!((0.0..1.0).contains(&u));
            assert!(standard_normal(&mut rng).is_finite());
        }
    }
}
