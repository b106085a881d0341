//! Paper 000 Eq. 2's time model of one robot, the two numbers the calibration fits.

use roam_planner::params::GaParams;
use roam_proto::planner::GaOverrides;
use serde::{Deserialize, Serialize};

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
}
