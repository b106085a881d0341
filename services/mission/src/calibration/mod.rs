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

mod config;
mod error;
pub mod fit;
pub mod store;
pub mod stretch;
mod time_model;

pub use config::CalibrationConfig;
pub use error::CalibrationError;
pub use fit::{fit, Calibration, Statistics, StretchSummary, WindowError};
pub use stretch::{path_measure, Sample, Stretch, MAX_STRETCH_SAMPLES};
pub use time_model::TimeModel;

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
