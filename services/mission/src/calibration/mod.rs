//! Calibrating paper 000's time model (Eq. 2) from what the robot drove.
//!
//! The planner estimates a path's driving time with Eq. 2, `t_ETA = v_lin·Σd + v_ang·Σθ`
//! (seconds per metre, seconds per radian; Table I: 2.0 and 1.0). Those are numbers of
//! the robot, not of the paper (DESIGN.md, "Time models"): with Table I's values the
//! sim's point robot drives about half of each window and waits the rest. This module
//! fits v_lin and v_ang to the robot's own driving, with Table I as the prior. Plain
//! Rust, no Zenoh: the executive feeds it and persists it.
//!
//! - [`stretch`]: what was driven, as (time, position) samples, one [`Stretch`] per
//!   mission (a replan starts a new one), cut into *chunks* (straight pieces and corners)
//!   with their distance, turn (measured as Eq. 2 counts it) and duration.
//! - [`fit`]: which chunks are driving (stops and jumps are left out), the weighted,
//!   prior-blended least squares, and [`Calibration`], which accumulates it per robot.
//! - [`store`]: the calibration on disk, one small JSON file per robot.
//!
//! The API the executive calls: [`Calibration::new`] or [`store::load`] at the start,
//! [`Calibration::add`] with each mission's stretch, [`Calibration::model`] (and
//! [`TimeModel::overrides`] for the next plan request), [`store::save`] after each
//! window, and [`TimeModel::window_error`] to report how well a model predicted a window.

pub mod fit;
pub mod store;
pub mod stretch;

use roam_planner::params::GaParams;
use roam_proto::planner::GaOverrides;
use serde::{Deserialize, Serialize};

pub use fit::{fit, Calibration, Statistics, StretchSummary, WindowError};
pub use stretch::{path_measure, Sample, Stretch, MAX_STRETCH_SAMPLES};

/// Paper 000 Eq. 2's time model of one robot: `t = v_lin·d + v_ang·θ`.
///
/// As the planner reads Eq. 2 (its `GaParams`), both are times per unit: Table I calls
/// them velocities (m/s, rad/s), but Eq. 2 multiplies them by distances and angles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeModel {
    /// Seconds per metre driven.
    pub v_lin: f64,
    /// Seconds per radian of heading change.
    pub v_ang: f64,
}

impl TimeModel {
    /// Paper 000 Table I's values, as the planner's defaults: v_lin 2.0 s/m, v_ang 1.0
    /// s/rad.
    pub fn table_i() -> TimeModel {
        let ga = GaParams::default();
        TimeModel {
            v_lin: ga.v_lin,
            v_ang: ga.v_ang,
        }
    }

    /// Eq. 2: the time to drive `distance_m` metres with `turn_rad` radians of turning.
    pub fn eta(&self, distance_m: f64, turn_rad: f64) -> f64 {
        self.v_lin * distance_m + self.v_ang * turn_rad
    }

    /// The planner overrides that make a plan request use this model.
    pub fn overrides(&self) -> GaOverrides {
        GaOverrides {
            v_lin: Some(self.v_lin),
            v_ang: Some(self.v_ang),
            ..GaOverrides::default()
        }
    }

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
    /// `(1 + stop_ratio)·predicted + stop_slack_s`, see [`fit`].
    pub stop_ratio: f64,
    pub stop_slack_s: f64,
    /// The prior's weight: it counts as this many metres of straight driving at the
    /// prior's v_lin (5 m) …
    pub prior_distance_m: f64,
    /// … and this many radians of turning in place at the prior's v_ang (π/2, a right
    /// angle). See [`fit`] for how data and prior are weighed.
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

/// Why a calibration call was refused. Reading a damaged file is not an error: it falls
/// back to the prior (see [`store::load`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    #[error("calibration field {field}: {reason}")]
    Config { field: String, reason: String },
    #[error(
        "a stretch holds at most {max} samples (limit max_stretch_samples): start a new stretch"
    )]
    TooManySamples { max: usize },
    #[error("cannot write the time calibration {path}: {reason}")]
    Write { path: String, reason: String },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq_2_and_the_overrides_a_plan_request_takes() {
        let m = TimeModel {
            v_lin: 1.25,
            v_ang: 1.5,
        };
        assert_eq!(m.eta(10.0, 2.0), 15.5);
        let o = m.overrides();
        assert_eq!((o.v_lin, o.v_ang), (Some(1.25), Some(1.5)));
        assert_eq!(
            TimeModel::table_i(),
            TimeModel {
                v_lin: 2.0,
                v_ang: 1.0
            }
        );
    }

    #[test]
    fn bad_priors_and_configs_are_refused_naming_the_field_and_the_range() {
        let config = CalibrationConfig::default();
        for (v_lin, v_ang, field) in [
            (0.0, 1.0, "prior.v_lin"),
            (-2.0, 1.0, "prior.v_lin"),
            (f64::NAN, 1.0, "prior.v_lin"),
            (2.0, 0.0, "prior.v_ang"),
            (2.0, -1.0, "prior.v_ang"),
            (2.0, f64::NAN, "prior.v_ang"),
            (2.0, 25.0, "prior.v_ang"),
        ] {
            let err = Calibration::new(TimeModel { v_lin, v_ang }, config).expect_err(field);
            let msg = err.to_string();
            assert!(msg.contains(&format!("field {field}:")), "{msg}");
            assert!(msg.contains("in 0.0") && msg.contains("..=20"), "{msg}");
        }
        for (bad, field) in [
            (
                CalibrationConfig {
                    spacing_m: 0.0,
                    ..config
                },
                "spacing_m",
            ),
            (
                CalibrationConfig {
                    prior_distance_m: f64::NAN,
                    ..config
                },
                "prior_distance_m",
            ),
            (
                CalibrationConfig {
                    stop_ratio: -1.0,
                    ..config
                },
                "stop_ratio",
            ),
            (
                CalibrationConfig {
                    min: TimeModel {
                        v_lin: 30.0,
                        v_ang: 0.01,
                    },
                    ..config
                },
                "min.v_lin",
            ),
        ] {
            let err = Calibration::new(TimeModel::table_i(), bad).expect_err(field);
            assert!(
                err.to_string().contains(&format!("field {field}:")),
                "{err}"
            );
        }
        // Scaled for noisy estimates, the config is still valid and coarser.
        let noisy = CalibrationConfig::for_position_noise(0.05);
        noisy.check().expect("valid");
        assert!(noisy.spacing_m > config.spacing_m && noisy.straight_rad > config.straight_rad);
    }
}
