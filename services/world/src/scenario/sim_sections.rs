//! The sim world's sections of a scenario file (anchors, sensing, time, blocks,
//! walkers, waypoints): their types, defaults and checks (`motion` and the robots'
//! starts are in [`super::motion`]; the check of all the sim sections against the map
//! in [`super::sim_check`]).

use serde::Deserialize;

use super::field_issue::FieldIssue;

/// Paper 002 §4's sensing range: 30 m.
pub const DEFAULT_RANGE_M: f64 = 30.0;
/// Paper 002 §4's σ_TOA: 0.10 m.
pub const DEFAULT_SIGMA_TOA_M: f64 = 0.10;
/// Paper 002 §4's d0: 15 m.
pub const DEFAULT_D0_M: f64 = 15.0;
/// Paper 002 §4's K: 2.
pub const DEFAULT_K: f64 = 2.0;
/// The fewest anchors a position is fixed from by default: three, as two range circles
/// meet in two points (roam's rule; paper 002 does not say).
pub const DEFAULT_FIX_ANCHORS: usize = 3;
/// The fewest anchors a site may fix from: two, where the robot's last fix tells the
/// two points apart (`sensing.fix_anchors`).
pub const FEWEST_FIX_ANCHORS: usize = 2;
/// The most a site may ask for: beyond this no UWB layout roam has seen would fix at all.
pub const MOST_FIX_ANCHORS: usize = 8;
/// roam's choice (no paper gives one for a laser-like grid observation): 5 m, about what
/// covers one of the 6 × 6 m rooms of paper 004's Stage world from inside it.
pub const DEFAULT_OBSERVATION_RADIUS_M: f64 = 5.0;
/// 0.4 s per step: with the default 0.2 m per step a robot drives at 0.5 m/s, the speed
/// paper 000's Table I implies (v_lin = 2.0 s/m) and the planner's t_ETA assumes. Paper
/// 002 counts steps, not seconds.
pub const DEFAULT_STEP_S: f64 = 0.4;
/// The largest observation radius, in cells: the line-of-sight table grows with the
/// cube of the radius (128 cells: about 50 k cells in view and a 25 MB table).
pub const MAX_OBSERVATION_RADIUS_CELLS: f64 = 128.0;
/// Occupancy values from which a cell blocks motion and sight in the sim world: the map
/// server's default `lethal_threshold`. Unknown cells (-1) block too: the sim needs a
/// definite ground truth, and a robot must not drive into space nobody mapped.
pub const BLOCKED_THRESHOLD: i8 = 65;

/// Whether an occupancy value blocks a robot and its sensors in the sim world.
pub fn is_blocked(value: i8) -> bool {
    !(0..BLOCKED_THRESHOLD).contains(&value)
}

/// Which ranges a robot receives (paper 002 §2.1 says both `d ≤ s_r` and `d̂ ≤ s_r`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RangeGate {
    /// Anchors whose true distance is within the range (§2.1's first reading): which
    /// anchors a robot hears depends on geometry alone, as the Fisher information does.
    #[default]
    TrueDistance,
    /// Measurements whose noisy value is within the range (§2.1's second reading).
    Measured,
}

/// The TOA range sensor (paper 002 §2.1, §4) and the local grid observation.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensingSpec {
    /// Sensing range s_r, metres (paper 002: 30).
    pub range_m: f64,
    /// Range noise standard deviation σ_TOA up to d0, metres (paper 002: 0.10).
    pub sigma_toa_m: f64,
    /// Distance d0 beyond which the noise grows, metres (paper 002: 15).
    pub d0_m: f64,
    /// Exponent K of the variance σ²((d/d0)^K + 1) beyond d0 (paper 002: 2), unitless.
    pub k: f64,
    /// Which ranges are delivered: by true distance (default) or by measured distance.
    pub range_gate: RangeGate,
    /// Radius of the local grid observation with line of sight, metres; 0 turns it off.
    pub observation_radius_m: f64,
    /// The fewest anchors in range that fix a position (default 3). 2 lets localization
    /// track through places where only two anchors are heard, from the robot's last fix:
    /// the two circles meet in two points and the one near the last fix is taken when
    /// the other is clearly farther (`roam_localization::wls`). The PEB field follows
    /// the same rule, so the planner and the controller's guard see the fix the
    /// estimator has. A site whose anchors leave gaps sets 2; the papers' worlds keep 3.
    pub fix_anchors: usize,
}

impl Default for SensingSpec {
    fn default() -> Self {
        SensingSpec {
            range_m: DEFAULT_RANGE_M,
            sigma_toa_m: DEFAULT_SIGMA_TOA_M,
            d0_m: DEFAULT_D0_M,
            k: DEFAULT_K,
            range_gate: RangeGate::default(),
            observation_radius_m: DEFAULT_OBSERVATION_RADIUS_M,
            fix_anchors: DEFAULT_FIX_ANCHORS,
        }
    }
}

/// The sim clock.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TimeSpec {
    /// Sim time per step, seconds.
    pub step_s: f64,
}

impl Default for TimeSpec {
    fn default() -> Self {
        TimeSpec {
            step_s: DEFAULT_STEP_S,
        }
    }
}

/// A scripted moving obstacle: it holds each position of `path` for `period_steps`
/// steps, then moves to the next, and starts over after the last (paper 004 §5: "changes
/// position every 7 time steps and moves over 6 positions").
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSpec {
    pub name: String,
    /// Width and height in cells: give this or `size_m`.
    #[serde(default)]
    pub size_cells: Option<[u32; 2]>,
    /// Width and height in metres, rounded to whole cells (at least one): give this or
    /// `size_cells`.
    #[serde(default)]
    pub size_m: Option<[f64; 2]>,
    /// The positions, world metres: each point picks the cell the block is centred on
    /// (for an even size the extra column or row is on the +x or +y side).
    pub path: Vec<[f64; 2]>,
    /// Steps the block holds each position, at least 1.
    pub period_steps: u32,
}

/// An obstacle that wanders: every `every_steps` steps it tries one move of `step_m` in
/// one of the four axis directions, drawn at random, and stays put when the place is
/// taken (a wall, a block, another walker, a robot) or off the map.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WalkerSpec {
    pub name: String,
    /// Start position, world metres, on a free cell.
    pub at: [f64; 2],
    /// Side of the square it covers, metres, rounded to whole cells (at least one).
    pub size_m: f64,
    /// Length of one move, metres.
    pub step_m: f64,
    /// Steps between two moves, at least 1.
    pub every_steps: u32,
}

impl SensingSpec {
    /// Checks every field; `resolution` (metres per cell) bounds the observation radius.
    pub fn check(&self, resolution: f64) -> Result<(), FieldIssue> {
        let positive = |f: &str, v: f64, unit: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(FieldIssue::new(
                    format!("sensing.{f}"),
                    format!("must be a positive number of {unit}, got {v}"),
                ))
            }
        };
        let non_negative = |f: &str, v: f64, unit: &str| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(FieldIssue::new(
                    format!("sensing.{f}"),
                    format!("must be a non-negative number of {unit}, got {v}"),
                ))
            }
        };
        positive("range_m", self.range_m, "metres")?;
        non_negative("sigma_toa_m", self.sigma_toa_m, "metres")?;
        positive("d0_m", self.d0_m, "metres")?;
        non_negative("k", self.k, "(a unitless exponent)")?;
        non_negative("observation_radius_m", self.observation_radius_m, "metres")?;
        if !(FEWEST_FIX_ANCHORS..=MOST_FIX_ANCHORS).contains(&self.fix_anchors) {
            return Err(FieldIssue::new(
                "sensing.fix_anchors",
                format!(
                    "must be {FEWEST_FIX_ANCHORS} to {MOST_FIX_ANCHORS} anchors, got {}",
                    self.fix_anchors
                ),
            ));
        }
        let cells = self.observation_radius_m / resolution;
        if cells > MAX_OBSERVATION_RADIUS_CELLS {
            return Err(FieldIssue::new(
                "sensing.observation_radius_m",
                format!(
                    "{} m is {cells:.0} cells of {resolution} m; the limit is \
                     {MAX_OBSERVATION_RADIUS_CELLS} cells ({} m on this map)",
                    self.observation_radius_m,
                    MAX_OBSERVATION_RADIUS_CELLS * resolution
                ),
            ));
        }
        Ok(())
    }
}

impl TimeSpec {
    /// Checks every field.
    pub fn check(&self) -> Result<(), FieldIssue> {
        if !(self.step_s.is_finite() && self.step_s > 0.0) {
            return Err(FieldIssue::new(
                "time.step_s",
                format!("must be a positive number of seconds, got {}", self.step_s),
            ));
        }
        Ok(())
    }
}
