//! The sim world's `motion` section and the robots' starts: which robot the sim drives
//! (paper 002's holonomic point, or roam's unicycle), its limits and noise, and where
//! and facing where each robot starts.

use serde::Deserialize;

use super::field_issue::FieldIssue;

/// Paper 002 §4's step size μ: 0.2.
pub const DEFAULT_STEP_MU: f64 = 0.2;
/// Paper 002 §4's σ_tr: 0.01 m.
pub const DEFAULT_SIGMA_TR_M: f64 = 0.01;
/// 0.2 m per step, μ times a unit command: paper 002's ES1 robot covers 59.56 m in 296
/// steps (0.201 m per step), so its commands have unit length at most.
pub const DEFAULT_MAX_SPEED_M_PER_STEP: f64 = 0.2;
/// The fastest unicycle, m/s (limit `max_v_m_per_s`): 72 km/h is beyond any robot roam
/// drives indoors, so a larger value is a typo (or another unit).
pub const MAX_UNICYCLE_V_M_PER_S: f64 = 20.0;
/// The fastest-turning unicycle, rad/s (limit `max_w_rad_per_s`): about three turns a
/// second; a larger value is most likely degrees per second.
pub const MAX_UNICYCLE_W_RAD_PER_S: f64 = 20.0;

/// How the sim's robots move: `p ← p + μ·u + ν`, ν ~ N(0, σ_tr²) per axis (paper 002
/// Eq. 1) for the default point robot; the unicycle follows the same command `u` with a
/// heading and turn rate (see [`MotionModel`]).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MotionSpec {
    /// Step size μ, metres per unit of command per step (paper 002: 0.2).
    pub step_mu: f64,
    /// Transition noise standard deviation σ_tr per axis, metres (paper 002: 0.01); 0
    /// makes motion deterministic (paper 004's grid world).
    pub sigma_tr_m: f64,
    /// The point model's longest commanded move μ·|u| in one step, metres; longer
    /// commands are clipped to this length. (The unicycle's top speed is its own
    /// `v_max_m_per_s`.)
    pub max_speed_m_per_step: f64,
    /// Which robot: `point` (default) or `{ unicycle: { v_max_m_per_s, w_max_rad_per_s } }`.
    pub model: MotionModel,
}

impl Default for MotionSpec {
    fn default() -> Self {
        MotionSpec {
            step_mu: DEFAULT_STEP_MU,
            sigma_tr_m: DEFAULT_SIGMA_TR_M,
            max_speed_m_per_step: DEFAULT_MAX_SPEED_M_PER_STEP,
            model: MotionModel::Point,
        }
    }
}

/// The robot the sim drives. Written as `model: point` or as a one-key map,
/// `model: { unicycle: { v_max_m_per_s: 0.5, w_max_rad_per_s: 1.0 } }`.
///
/// Paper 000's Eq. 2 charges turning (`v_ang · Σθ`), paper 002's Eq. 1 robot does not
/// turn at all: a point robot needs about half the time Eq. 2 with Table I plans for.
/// The unicycle is roam's addition, so that a scenario can have a robot that pays for
/// its turns and the time model (v_lin, v_ang) can be calibrated against one.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum MotionModel {
    /// Paper 002 Eq. 1: a holonomic point, no heading; the move μ·u is clipped to
    /// `max_speed_m_per_step`. Today's behaviour, bit for bit.
    #[default]
    Point,
    /// roam's unicycle (a differential-drive robot): a heading, a top speed and a top
    /// turn rate; it turns toward the command in place, then drives (see roam-sim's
    /// `robot` module for the rule).
    Unicycle(UnicycleSpec),
}

/// The unicycle's limits.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnicycleSpec {
    /// Top forward speed v_max, m/s: at most v_max · `time.step_s` metres per step.
    pub v_max_m_per_s: f64,
    /// Top turn rate w_max, rad/s: at most w_max · `time.step_s` radians per step.
    pub w_max_rad_per_s: f64,
}

/// A robot of the scenario: its name, where it starts (world metres, on a free cell)
/// and which way it faces there.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotStart {
    pub name: String,
    pub at: [f64; 2],
    /// Heading at the start, radians counter-clockwise from +x (default 0: facing +x).
    /// Only the unicycle has a heading; the point model ignores it.
    #[serde(default)]
    pub heading_rad: f64,
}

impl MotionSpec {
    /// Checks every field.
    pub fn check(&self) -> Result<(), FieldIssue> {
        if !(self.step_mu.is_finite() && self.step_mu > 0.0) {
            return Err(FieldIssue::new(
                "motion.step_mu",
                format!("must be a positive number, got {}", self.step_mu),
            ));
        }
        if !(self.sigma_tr_m.is_finite() && self.sigma_tr_m >= 0.0) {
            return Err(FieldIssue::new(
                "motion.sigma_tr_m",
                format!(
                    "must be a non-negative number of metres, got {}",
                    self.sigma_tr_m
                ),
            ));
        }
        if !(self.max_speed_m_per_step.is_finite() && self.max_speed_m_per_step > 0.0) {
            return Err(FieldIssue::new(
                "motion.max_speed_m_per_step",
                format!(
                    "must be a positive number of metres per step, got {}",
                    self.max_speed_m_per_step
                ),
            ));
        }
        match self.model {
            MotionModel::Point => Ok(()),
            MotionModel::Unicycle(u) => u.check(),
        }
    }
}

impl UnicycleSpec {
    /// Checks both limits: positive, finite, and below a bound that catches a wrong unit.
    pub fn check(&self) -> Result<(), FieldIssue> {
        let bounded = |field: &str, v: f64, unit: &str, max: f64, limit: &str| {
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(())
            } else {
                Err(FieldIssue::new(
                    format!("motion.model.unicycle.{field}"),
                    format!(
                        "must be a positive number of {unit} greater than 0 and at most \
                         {max} (limit {limit}), got {v}"
                    ),
                ))
            }
        };
        bounded(
            "v_max_m_per_s",
            self.v_max_m_per_s,
            "metres per second",
            MAX_UNICYCLE_V_M_PER_S,
            "max_v_m_per_s",
        )?;
        bounded(
            "w_max_rad_per_s",
            self.w_max_rad_per_s,
            "radians per second",
            MAX_UNICYCLE_W_RAD_PER_S,
            "max_w_rad_per_s",
        )
    }
}

impl RobotStart {
    /// Checks the heading (the position is checked against the map by the caller);
    /// `field` is the robot's path in the file, e.g. `robots[0]`.
    pub fn check_heading(&self, field: &str) -> Result<(), FieldIssue> {
        if self.heading_rad.is_finite() {
            Ok(())
        } else {
            Err(FieldIssue::new(
                format!("{field}.heading_rad"),
                format!(
                    "robot '{}': must be a finite number of radians, got {}",
                    self.name, self.heading_rad
                ),
            ))
        }
    }
}
