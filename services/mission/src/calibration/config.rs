//! How driven paths are measured and fitted, and the plausible range of a fit that a
//! time model is checked against.

use serde::{Deserialize, Serialize};

use super::error::CalibrationError;
use super::time_model::TimeModel;

/// How driven paths are measured and fitted. The defaults suit positions as good as
/// the sim's ground truth (σ ≲ 0.02 m); [`CalibrationConfig::for_position_noise`] scales
/// them for noisier estimates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CalibrationConfig {
    /// Driven positions are resampled at this spacing before distances and turns are
    /// measured, metres: a knot is kept when the robot is this far from the last one.
    /// Position noise σ tilts a knot-to-knot direction by about √2·σ/spacing, so the
    /// spacing must be well above σ (0.5 m: 0.03 rad at σ = 0.01 m).
    pub spacing_m: f64,
    /// A heading change at a knot below this is taken for noise on a straight line,
    /// radians; at or above it the knot is part of a corner.
    pub straight_rad: f64,
    /// The tolerance of the simplification that measures a corner's driven length
    /// (Douglas–Peucker over the samples), metres.
    pub corner_tolerance_m: f64,
    /// Samples further apart in time than this start a new run (the estimates stopped:
    /// what happened in between is unknown), seconds.
    pub max_sample_gap_s: f64,
    /// A chunk is a stop (the robot waited) when it took longer than
    /// `(1 + stop_ratio)·predicted + stop_slack_s`, see [`super::fit`].
    pub stop_ratio: f64,
    pub stop_slack_s: f64,
    /// The prior's weight: it counts as this many metres of straight driving at the
    /// prior's v_lin (5 m) …
    pub prior_distance_m: f64,
    /// … and this many radians of turning in place at the prior's v_ang (π/2, a right
    /// angle). See [`super::fit`] for how data and prior are weighed.
    pub prior_turn_rad: f64,
    /// The fit remembers about this many seconds of driving: beyond it, older data is
    /// scaled down so that the sums hold this much (a robot changes: load, wear).
    pub memory_s: f64,
    /// The plausible range of a fit; a fit outside it is clamped to it.
    pub min: TimeModel,
    pub max: TimeModel,
}

impl Default for CalibrationConfig {
    fn default() -> Self {
        CalibrationConfig {
            spacing_m: 0.5,
            straight_rad: 0.15,
            corner_tolerance_m: 0.125,
            max_sample_gap_s: 5.0,
            stop_ratio: 0.5,
            stop_slack_s: 1.0,
            prior_distance_m: 5.0,
            prior_turn_rad: std::f64::consts::FRAC_PI_2,
            memory_s: 3600.0,
            min: TimeModel {
                v_lin: 0.05,
                v_ang: 0.01,
            },
            max: TimeModel {
                v_lin: 20.0,
                v_ang: 20.0,
            },
        }
    }
}

impl CalibrationConfig {
    /// The defaults with the spacing, the straight-line threshold and the corner
    /// tolerance scaled for white position noise `sigma_m` (per axis, metres): spacing
    /// at least 12σ, the threshold two standard deviations of a knot's heading change
    /// (2·√6·σ/spacing), the tolerance at least 5σ.
    ///
    /// Measuring from positions alone degrades with their noise: in the sim test
    /// (`tests/calibration.rs`, a zig-zag with legs of 2.7 to 4.5 m, a sample every
    /// 0.4 s) the fit is within 5% of the truth at σ = 0.02 m and within 10% at 0.05 m
    /// (TOA estimates); at 0.1 m the corners are lost in the noise. Feed the best
    /// positions there are (ground truth in the sim, odometry, smoothed estimates).
    pub fn for_position_noise(sigma_m: f64) -> CalibrationConfig {
        let d = CalibrationConfig::default();
        let sigma = if sigma_m.is_finite() {
            sigma_m.max(0.0)
        } else {
            0.0
        };
        let spacing_m = d.spacing_m.max(12.0 * sigma);
        CalibrationConfig {
            spacing_m,
            straight_rad: d.straight_rad.max(2.0 * 6f64.sqrt() * sigma / spacing_m),
            corner_tolerance_m: (spacing_m / 4.0).max(5.0 * sigma),
            ..d
        }
    }

    /// Checks every field, naming it and its range.
    pub fn check(&self) -> Result<(), CalibrationError> {
        let bad = |field: &str, reason: String| {
            Err(CalibrationError::Config {
                field: field.to_owned(),
                reason,
            })
        };
        for (field, v, lo, hi, unit) in [
            ("spacing_m", self.spacing_m, 1e-3, 100.0, "metres"),
            (
                "straight_rad",
                self.straight_rad,
                1e-3,
                std::f64::consts::FRAC_PI_2,
                "radians",
            ),
            (
                "corner_tolerance_m",
                self.corner_tolerance_m,
                1e-4,
                100.0,
                "metres",
            ),
            (
                "max_sample_gap_s",
                self.max_sample_gap_s,
                1e-3,
                3600.0,
                "seconds",
            ),
            (
                "prior_distance_m",
                self.prior_distance_m,
                1e-3,
                1e6,
                "metres",
            ),
            ("prior_turn_rad", self.prior_turn_rad, 1e-3, 1e6, "radians"),
            ("memory_s", self.memory_s, 1.0, 1e9, "seconds"),
        ] {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return bad(
                    field,
                    format!("must be a number of {unit} in {lo}..={hi}, got {v}"),
                );
            }
        }
        for (field, v) in [
            ("stop_ratio", self.stop_ratio),
            ("stop_slack_s", self.stop_slack_s),
        ] {
            if !(v.is_finite() && (0.0..=1e6).contains(&v)) {
                return bad(field, format!("must be a number in 0..=1000000, got {v}"));
            }
        }
        for (name, lo, hi) in [
            ("v_lin", self.min.v_lin, self.max.v_lin),
            ("v_ang", self.min.v_ang, self.max.v_ang),
        ] {
            if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi) {
                return bad(
                    &format!("min.{name}"),
                    format!("the range {lo}..={hi} must be finite, positive and not empty"),
                );
            }
        }
        Ok(())
    }
}

// A time model's check lives beside the bounds it is checked against.
impl TimeModel {
    /// Whether both are finite, positive and within `config`'s bounds; `field` names
    /// the model in the error (e.g. `prior`).
    pub fn check(&self, field: &str, config: &CalibrationConfig) -> Result<(), CalibrationError> {
        for (name, v, lo, hi, unit) in [
            (
                "v_lin",
                self.v_lin,
                config.min.v_lin,
                config.max.v_lin,
                "s/m",
            ),
            (
                "v_ang",
                self.v_ang,
                config.min.v_ang,
                config.max.v_ang,
                "s/rad",
            ),
        ] {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(CalibrationError::Config {
                    field: format!("{field}.{name}"),
                    reason: format!("must be a number of {unit} in {lo}..={hi}, got {v}"),
                });
            }
        }
        Ok(())
    }
}
