//! The TOA ranging model of paper 002 §2.1: fixed anchors at known positions, a sensing
//! range s_r, and Gaussian range noise whose variance grows beyond d0.
//!
//! The variance itself is roam-sim's [`ToaNoise`] (σ² up to d0, σ²((d/d0)^K + 1) beyond,
//! K read as an exponent, the literal step from σ² to 2σ² at d0 kept): the estimator
//! and the bound must model exactly the noise the sim draws, so the formula lives in
//! one place.

use nalgebra::Vector2;
use roam_world::noise::ToaNoise;
use roam_world::scenario::{
    SensingSpec, DEFAULT_FIX_ANCHORS, FEWEST_FIX_ANCHORS, MOST_FIX_ANCHORS,
};

use crate::error::LocalizationError;

/// The most anchors one model holds: the estimator and the field are linear in it, and a
/// request naming more is refused rather than allowed to grow without bound.
pub const MAX_ANCHORS: usize = 4096;

/// Below this distance (metres) an anchor's direction from the point is undefined, so it
/// contributes no information there (paper 002's FIM uses the unit vector to the anchor).
pub const MIN_DISTANCE_M: f64 = 1e-9;

/// The ranging model: anchor positions, sensing range and noise (paper 002 §2.1).
#[derive(Debug, Clone, PartialEq)]
pub struct RangingModel {
    anchors: Vec<Vector2<f64>>,
    sensing_range_m: f64,
    noise: ToaNoise,
    fix_anchors: usize,
}

impl RangingModel {
    /// A model from anchor positions (world metres), the sensing range s_r (metres) and
    /// the noise. Refuses non-finite positions, a non-positive range or σ or d0, a
    /// negative or non-finite K, and more than [`MAX_ANCHORS`] anchors.
    pub fn new(
        anchors: &[[f64; 2]],
        sensing_range_m: f64,
        noise: ToaNoise,
    ) -> Result<RangingModel, LocalizationError> {
        if anchors.len() > MAX_ANCHORS {
            return Err(LocalizationError::TooManyAnchors {
                count: anchors.len(),
                max: MAX_ANCHORS,
            });
        }
        for (i, a) in anchors.iter().enumerate() {
            if !(a[0].is_finite() && a[1].is_finite()) {
                return Err(LocalizationError::BadAnchor { index: i, at: *a });
            }
        }
        let positive = |name: &'static str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(LocalizationError::BadParameter {
                    name,
                    value: v,
                    expected: "a positive finite number",
                })
            }
        };
        positive("sensing range", sensing_range_m)?;
        positive("sigma_toa", noise.sigma_m)?;
        positive("d0", noise.d0_m)?;
        if !(noise.k.is_finite() && noise.k >= 0.0) {
            return Err(LocalizationError::BadParameter {
                name: "k",
                value: noise.k,
                expected: "a non-negative finite number",
            });
        }
        Ok(RangingModel {
            anchors: anchors.iter().map(|a| Vector2::new(a[0], a[1])).collect(),
            sensing_range_m,
            noise,
            fix_anchors: DEFAULT_FIX_ANCHORS,
        })
    }

    /// A model from a scenario's anchors and `sensing` section.
    pub fn from_spec(
        anchors: &[[f64; 2]],
        spec: &SensingSpec,
    ) -> Result<RangingModel, LocalizationError> {
        RangingModel::new(anchors, spec.range_m, ToaNoise::from_spec(spec))?
            .with_fix_anchors(spec.fix_anchors)
    }

    /// The same model fixing positions from `fix_anchors` anchors in range (at least
    /// [`FEWEST_FIX_ANCHORS`], at most [`MOST_FIX_ANCHORS`]): `sensing.fix_anchors`.
    pub fn with_fix_anchors(
        mut self,
        fix_anchors: usize,
    ) -> Result<RangingModel, LocalizationError> {
        if !(FEWEST_FIX_ANCHORS..=MOST_FIX_ANCHORS).contains(&fix_anchors) {
            return Err(LocalizationError::BadParameter {
                name: "fix_anchors",
                value: fix_anchors as f64,
                expected: "2 to 8 anchors",
            });
        }
        self.fix_anchors = fix_anchors;
        Ok(self)
    }

    /// The fewest anchors in range a position is fixed from (3 unless the scenario's
    /// `sensing.fix_anchors` says 2: see [`crate::wls`] for how two anchors fix).
    pub fn fix_anchors(&self) -> usize {
        self.fix_anchors
    }

    /// The anchor positions.
    pub fn anchors(&self) -> &[Vector2<f64>] {
        &self.anchors
    }

    /// The sensing range s_r, metres.
    pub fn sensing_range_m(&self) -> f64 {
        self.sensing_range_m
    }

    /// The noise model.
    pub fn noise(&self) -> &ToaNoise {
        &self.noise
    }

    /// Whether an anchor at distance `d` is heard (paper 002 §2.1: d ≤ s_r).
    pub fn in_range(&self, d: f64) -> bool {
        d <= self.sensing_range_m
    }

    /// The range noise variance v(d), m² (paper 002 §2.1; roam-sim's [`ToaNoise`]).
    pub fn variance(&self, d: f64) -> f64 {
        self.noise.variance(d)
    }

    /// dv/dd, m (paper 002 §2.1 differentiated): 0 up to d0, σ²·K·d^(K−1)/d0^K beyond.
    /// The step at d0 (σ² to 2σ²) has no finite derivative; it is ignored (one-sided
    /// derivatives), as a FIM is defined point by point away from it.
    pub fn variance_derivative(&self, d: f64) -> f64 {
        let n = &self.noise;
        if d <= n.d0_m {
            0.0
        } else {
            let s2 = n.sigma_m * n.sigma_m;
            s2 * n.k * (d / n.d0_m).powf(n.k - 1.0) / n.d0_m
        }
    }

    /// The weight of one range in the FIM at distance `d` (paper 002 §2.2 with §2.1's
    /// noise): 1/v + [v′²/(2v²) if `variance_derivative`]. For a Gaussian range whose
    /// variance depends on the unknown distance, the Fisher information about d is
    /// 1/v (from the mean) + v′²/(2v²) (from the variance).
    pub fn range_information(&self, d: f64, variance_derivative: bool) -> f64 {
        let v = self.variance(d);
        let mut w = 1.0 / v;
        if variance_derivative {
            let dv = self.variance_derivative(d);
            w += dv * dv / (2.0 * v * v);
        }
        w
    }
}
