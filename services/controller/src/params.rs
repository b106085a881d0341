//! The controller's parameters: paper 002 §4's values are the defaults, and roam's safety
//! parameters (not in the paper) say when a mission is given up. Every value is checked
//! by [`ApfParams::check`], which names the parameter and its allowed range.

use serde::{Deserialize, Serialize};

use crate::weights::Scheme;

/// Paper 002 §4: z_a = 1.0.
pub const DEFAULT_Z_A: f64 = 1.0;
/// Paper 002 §4: z_r = 20.0.
pub const DEFAULT_Z_R: f64 = 20.0;
/// Paper 002 §4: the repulsive potential's influence range η_thres = 3.0 m.
pub const DEFAULT_ETA_THRES_M: f64 = 3.0;
/// Paper 002 §4: a waypoint is reached within g_thres = 0.10 m.
pub const DEFAULT_G_THRES_M: f64 = 0.10;
/// g_thres indoors ([`ApfParams::indoor`]), metres: above what localization can tell.
/// Paper 002's 0.10 m is for a robot on its true position (ES1–ES3). On TOA estimates
/// (σ ≈ 0.1 m per axis, a median RMS error of 0.12 m in the built-in day) a robot at
/// its goal is inside 0.10 m by its estimate only about every other update, and paper
/// 002's unit f_a steps it μ = 0.2 m toward each noisy estimate, across the goal and
/// back: measured in `roam reproduce mission`, robots dithered 5–14 s within 0.3 m of
/// the dock and of home before an estimate fell inside, and every late window of the
/// roam variants (2 of 200 each) was such a dither after a drive predicted at 0.2–2.6
/// s. At 0.2 m (one cell of the built-in grid, whose cell centres the planned path ends
/// on, up to 0.14 m from the task's place anyway; Nav2's default goal tolerance is
/// 0.25 m) a step aimed at the goal cannot cross the circle, and none was late.
pub const INDOOR_G_THRES_M: f64 = 0.2;
/// Paper 002 §4: the simulation ends after max_steps = 10 000 steps.
pub const DEFAULT_MAX_STEPS: u64 = 10_000;
/// Paper 002 §4 ES1: z_is = 0.8.
pub const DEFAULT_Z_IS: f64 = 0.8;
/// The adaptation threshold ω_t. Paper 002 does not state it; ES1's cutoff robot "due
/// to its setup (i.e. ω = 90°…)" implies 90°.
pub const DEFAULT_OMEGA_T_DEG: f64 = 90.0;
/// The share of z_is the cutoff scheme keeps above ω_t (paper 002 §3.1: "a percentage of
/// z_is or completely disabled"; Eq. 2 and ES1 use 0).
pub const DEFAULT_CUTOFF_KEEP: f64 = 0.0;
/// roam's safety bound on the PEB, metres (not in paper 002).
pub const DEFAULT_MAX_PEB_M: f64 = 2.0;
/// roam's stuck window, updates (not in paper 002).
pub const DEFAULT_STUCK_WINDOW_STEPS: u64 = 300;
/// The stuck window of [`ApfParams::fleet`], updates: 10 s at a 0.4 s step.
pub const FLEET_STUCK_WINDOW_STEPS: u64 = 25;
/// roam's least progress over the stuck window, metres (not in paper 002).
pub const DEFAULT_STUCK_MIN_PROGRESS_M: f64 = 0.25;
/// Paper 002 §4's step size μ = 0.2 m (Eq. 1), also the built-in world's (roam-sim's
/// default `step_mu`, with a top speed of 0.2 m per step).
pub const PAPER_STEP_MU_M: f64 = 0.2;
/// The carrot's lookahead L under `follow: path`, metres: one and a half steps μ (0.3 m,
/// one and a half cells of the built-in world's 0.2 m grid). More than a step, so the
/// robot does not reach its carrot in one step on a straight stretch and the estimate's
/// noise (σ about 0.1 m) does not steer every step; short enough that the GA's one-cell
/// detours are driven and not smoothed away, and that the IS force (z_is 0.3 indoors,
/// at right angles to the path) holds the robot at most about L·z_is/√(1 − z_is²) ≈
/// 0.09 m off it. Measured in the built-in world (`roam reproduce mission`, the median
/// of driven / planned information): 0.2 m gathers slightly more but wiggles (7% more
/// steps on a straight line), 0.4 m cuts the small detours (0.945 against 0.987).
pub const DEFAULT_LOOKAHEAD_M: f64 = 0.3;
/// The projection's search window under `follow: path`, in lookaheads: each update
/// searches at most 2 L of the path ahead of the last projection.
pub const WINDOW_LOOKAHEADS: f64 = 2.0;

/// What the attractive force pulls toward (roam's choice; paper 002 §3 has the first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Follow {
    /// Paper 002 §3: f_a toward the current waypoint; a waypoint within g_thres (or
    /// `via_thres_m`) is passed and the next becomes current. Straight between
    /// waypoints: the paper's experiments (ES1–ES3) and missions whose waypoints are
    /// places.
    Waypoints,
    /// Pure pursuit on the path ([`crate::carrot`]): f_a toward the carrot `lookahead_m`
    /// ahead, along the polyline from the robot's position at the mission's start
    /// through its waypoints, of the robot's projection onto it (searched forward
    /// only). Complete within g_thres of the last point. For missions that are a planned
    /// path, which should be driven as planned (the mission executive's).
    Path,
}

/// The largest step limit a mission may have.
pub const MAX_MAX_STEPS: u64 = 10_000_000;
/// The largest force weight (z_a, z_r, z_is) accepted.
pub const MAX_WEIGHT: f64 = 1e6;

/// The APF controller's parameters (paper 002 §3–4), with units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ApfParams {
    /// z_a, the attractive force's weight (paper 002 Eq. 3), unitless.
    pub z_a: f64,
    /// z_r, the repulsive force's weight (paper 002 Eq. 3), unitless.
    pub z_r: f64,
    /// η_thres, the repulsive potential's influence range, metres (paper 002 §4).
    pub eta_thres_m: f64,
    /// g_thres, the distance within which a waypoint counts as reached, metres.
    pub g_thres_m: f64,
    /// The distance within which a waypoint that is not the mission's last counts as
    /// passed, metres; `None` means g_thres (paper 002 §4 uses g_thres for every
    /// waypoint). A mission executive that hands over a planned path as many waypoints
    /// wants a looser value: only the last one is a place the robot must reach exactly.
    /// Unused under `follow: path`, which passes no waypoint but follows the path.
    pub via_thres_m: Option<f64>,
    /// Updates a mission may take before it ends as `step_limit` (paper 002 §4).
    pub max_steps: u64,
    /// z_is, the information-seeking weight (paper 002 Eqs. 2–3), unitless.
    pub z_is: f64,
    /// ω_t, the adaptation threshold of Eq. 2, degrees in [0, 180].
    pub omega_t_deg: f64,
    /// The share of z_is the cutoff scheme keeps above ω_t, in [0, 1].
    pub cutoff_keep: f64,
    /// How z_is adapts to ω (paper 002 Eq. 2), or `plain` for no IS force. roam's
    /// default is `linear`, paper 002's fastest scheme that reached B in ES1.
    pub scheme: Scheme,
    /// Safety, not in paper 002: a robot whose PEB is above this (or unbounded: a lost
    /// fix) gets a zero command and the status `halted_peb` while it lasts, metres.
    /// +∞ turns the guard off (the unbounded PEB included): paper 002's ES2 runs on true
    /// positions, where a lost fix does not matter.
    pub max_peb_m: f64,
    /// Safety, not in paper 002: when the best distance to the current waypoint has not
    /// improved by `stuck_min_progress_m` over this many (unhalted) updates, the mission
    /// ends as `stuck` (a local minimum or an oscillation).
    pub stuck_window_steps: u64,
    /// See `stuck_window_steps`, metres. Under `follow: path` the distance is the one
    /// left along the path (from the robot to its projection, then the rest).
    pub stuck_min_progress_m: f64,
    /// How the mission is followed: `waypoints` (paper 002, the default) or `path`
    /// (pure pursuit on the polyline; roam's mission executive).
    pub follow: Follow,
    /// L, the carrot's lookahead along the path under `follow: path`, metres
    /// ([`DEFAULT_LOOKAHEAD_M`]: 1.5 steps μ, 0.3 m). It should be more than the
    /// robot's longest step (the sim's top speed per step), which the projection's
    /// window (2 L per update) then also exceeds. Unused under `waypoints`.
    pub lookahead_m: f64,
}

impl Default for ApfParams {
    fn default() -> Self {
        ApfParams {
            z_a: DEFAULT_Z_A,
            z_r: DEFAULT_Z_R,
            eta_thres_m: DEFAULT_ETA_THRES_M,
            g_thres_m: DEFAULT_G_THRES_M,
            via_thres_m: None,
            max_steps: DEFAULT_MAX_STEPS,
            z_is: DEFAULT_Z_IS,
            omega_t_deg: DEFAULT_OMEGA_T_DEG,
            cutoff_keep: DEFAULT_CUTOFF_KEEP,
            scheme: Scheme::Linear,
            max_peb_m: DEFAULT_MAX_PEB_M,
            stuck_window_steps: DEFAULT_STUCK_WINDOW_STEPS,
            stuck_min_progress_m: DEFAULT_STUCK_MIN_PROGRESS_M,
            follow: Follow::Waypoints,
            lookahead_m: DEFAULT_LOOKAHEAD_M,
        }
    }
}

use roam_world::param::check_param as check;
pub use roam_world::param::ParamError;

impl ApfParams {
    /// Parameters for buildings like the built-in world. Paper 002's η_thres = 3 m and
    /// z_r = 20 suit its open 50–70 m fields; in a 20 m building with 2 m doors they
    /// would push the robot out of every door (1 m from a jamb the repulsion is 13 times
    /// the attraction). Here the repulsion reaches 0.6 m, the robot's radius plus a
    /// margin (a planned path already keeps the inflation radius from walls), and IS is
    /// gentle (z_is 0.3): the building's anchors cover it well. A mission executive
    /// hands a planned path over as many waypoints, to be driven as planned: the path is
    /// followed as a path (`follow: path`, L = [`DEFAULT_LOOKAHEAD_M`]), and only the
    /// last point is a place to reach exactly. Under `follow: waypoints` the other
    /// waypoints are passed within `via_thres_m` 0.5 m.
    ///
    /// The goal is reached within [`INDOOR_G_THRES_M`], not paper 002's 0.10 m: see there.
    pub fn indoor() -> ApfParams {
        ApfParams {
            g_thres_m: INDOOR_G_THRES_M,
            eta_thres_m: 0.6,
            z_r: 0.05,
            z_is: 0.3,
            via_thres_m: Some(0.5),
            follow: Follow::Path,
            lookahead_m: DEFAULT_LOOKAHEAD_M,
            ..ApfParams::default()
        }
    }

    /// [`ApfParams::indoor`] for a fleet's shift: a robot that makes no progress for
    /// [`FLEET_STUCK_WINDOW_STEPS`] updates is stuck. The default window (300 updates,
    /// 120 s at the warehouse's 0.4 s step) outlasts a fleet's downtime windows (30 s to
    /// 4 minutes) and the executive's 60 s grace after a task's start, so a robot pushing
    /// against a pallet the static map does not have would stay `Active`, never stuck,
    /// never replanned, until its task is given up.
    pub fn fleet() -> ApfParams {
        ApfParams {
            stuck_window_steps: FLEET_STUCK_WINDOW_STEPS,
            ..ApfParams::indoor()
        }
    }

    /// Refuses a value the controller cannot work with, naming it and its range.
    pub fn check(&self) -> Result<(), ParamError> {
        let weight = |v: f64| (0.0..=MAX_WEIGHT).contains(&v);
        check("z_a", self.z_a, weight(self.z_a), "0 to 1e6")?;
        check("z_r", self.z_r, weight(self.z_r), "0 to 1e6")?;
        check("z_is", self.z_is, weight(self.z_is), "0 to 1e6")?;
        check(
            "eta_thres_m",
            self.eta_thres_m,
            self.eta_thres_m > 0.0 && self.eta_thres_m <= 1e4,
            "more than 0 up to 1e4 metres",
        )?;
        check(
            "g_thres_m",
            self.g_thres_m,
            self.g_thres_m > 0.0 && self.g_thres_m <= 1e4,
            "more than 0 up to 1e4 metres",
        )?;
        if let Some(via) = self.via_thres_m {
            check(
                "via_thres_m",
                via,
                via > 0.0 && via <= 1e4,
                "more than 0 up to 1e4 metres",
            )?;
        }
        check(
            "max_steps",
            self.max_steps as f64,
            (1..=MAX_MAX_STEPS).contains(&self.max_steps),
            "1 to 10000000",
        )?;
        check(
            "omega_t_deg",
            self.omega_t_deg,
            (0.0..=180.0).contains(&self.omega_t_deg),
            "0 to 180 degrees",
        )?;
        check(
            "cutoff_keep",
            self.cutoff_keep,
            (0.0..=1.0).contains(&self.cutoff_keep),
            "0 to 1",
        )?;
        // +∞ is allowed: it turns the PEB guard off.
        if self.max_peb_m.is_nan() || self.max_peb_m <= 0.0 {
            return Err(ParamError {
                name: "max_peb_m",
                value: self.max_peb_m,
                range: "more than 0 metres (infinity turns the guard off)",
            });
        }
        check(
            "stuck_window_steps",
            self.stuck_window_steps as f64,
            (1..=MAX_MAX_STEPS).contains(&self.stuck_window_steps),
            "1 to 10000000",
        )?;
        check(
            "stuck_min_progress_m",
            self.stuck_min_progress_m,
            self.stuck_min_progress_m >= 0.0 && self.stuck_min_progress_m <= 1e4,
            "0 to 1e4 metres",
        )?;
        check(
            "lookahead_m",
            self.lookahead_m,
            self.lookahead_m > 0.0 && self.lookahead_m <= 1e4,
            "more than 0 up to 1e4 metres",
        )
    }

    /// The projection's search window under `follow: path`, metres
    /// ([`WINDOW_LOOKAHEADS`] · L).
    pub fn window_m(&self) -> f64 {
        WINDOW_LOOKAHEADS * self.lookahead_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fleets_parameters_are_indoor_with_a_short_stuck_window() {
        let fleet = ApfParams::fleet();
        assert_eq!(fleet.check(), Ok(()));
        assert_eq!(fleet.stuck_window_steps, FLEET_STUCK_WINDOW_STEPS);
        assert_eq!(
            ApfParams {
                stuck_window_steps: DEFAULT_STUCK_WINDOW_STEPS,
                ..fleet
            },
            ApfParams::indoor()
        );
    }

    #[test]
    fn the_defaults_are_paper_002s_and_pass() {
        let p = ApfParams::default();
        assert_eq!((p.z_a, p.z_r, p.eta_thres_m), (1.0, 20.0, 3.0));
        assert_eq!((p.g_thres_m, p.max_steps, p.z_is), (0.10, 10_000, 0.8));
        assert_eq!((p.omega_t_deg, p.cutoff_keep), (90.0, 0.0));
        assert_eq!((p.follow, p.lookahead_m), (Follow::Waypoints, 0.3));
        assert!((DEFAULT_LOOKAHEAD_M - 1.5 * PAPER_STEP_MU_M).abs() < 1e-12);
        assert_eq!(p.check(), Ok(()));
        let indoor = ApfParams::indoor();
        assert_eq!((indoor.follow, indoor.lookahead_m), (Follow::Path, 0.3));
        assert_eq!(indoor.check(), Ok(()));
    }

    #[test]
    fn bad_values_are_named() {
        let bad = |p: ApfParams| p.check().err().map(|e| e.name);
        let d = ApfParams::default;
        assert_eq!(bad(ApfParams { z_a: -1.0, ..d() }), Some("z_a"));
        assert_eq!(
            bad(ApfParams {
                z_is: f64::NAN,
                ..d()
            }),
            Some("z_is")
        );
        assert_eq!(
            bad(ApfParams {
                eta_thres_m: 0.0,
                ..d()
            }),
            Some("eta_thres_m")
        );
        assert_eq!(
            bad(ApfParams {
                g_thres_m: -0.1,
                ..d()
            }),
            Some("g_thres_m")
        );
        assert_eq!(
            bad(ApfParams {
                max_steps: 0,
                ..d()
            }),
            Some("max_steps")
        );
        assert_eq!(
            bad(ApfParams {
                omega_t_deg: 181.0,
                ..d()
            }),
            Some("omega_t_deg")
        );
        assert_eq!(
            bad(ApfParams {
                cutoff_keep: 1.5,
                ..d()
            }),
            Some("cutoff_keep")
        );
        assert_eq!(
            bad(ApfParams {
                max_peb_m: 0.0,
                ..d()
            }),
            Some("max_peb_m")
        );
        assert_eq!(
            bad(ApfParams {
                max_peb_m: f64::NAN,
                ..d()
            }),
            Some("max_peb_m")
        );
        assert_eq!(
            bad(ApfParams {
                max_peb_m: f64::INFINITY,
                ..d()
            }),
            None
        );
        assert_eq!(
            bad(ApfParams {
                stuck_window_steps: 0,
                ..d()
            }),
            Some("stuck_window_steps")
        );
        for lookahead_m in [0.0, -0.4, f64::INFINITY, f64::NAN] {
            assert_eq!(bad(ApfParams { lookahead_m, ..d() }), Some("lookahead_m"));
        }
        let e = ApfParams {
            cutoff_keep: 2.0,
            ..d()
        }
        .check()
        .err()
        .map(|e| e.to_string());
        assert_eq!(
            e.as_deref(),
            Some("parameter cutoff_keep = 2 is out of range; use 0 to 1")
        );
    }

    #[test]
    fn a_config_embeds_it_with_defaults_and_refuses_typos() {
        let p: ApfParams =
            serde_json::from_str(r#"{"scheme": "sinusoidal", "z_is": 0.9}"#).expect("parse");
        assert_eq!(p.scheme, Scheme::Sinusoidal);
        assert_eq!(p.z_is, 0.9);
        assert_eq!(p.z_r, 20.0);
        assert!(serde_json::from_str::<ApfParams>(r#"{"zis": 0.9}"#).is_err());
        assert!(serde_json::from_str::<ApfParams>(r#"{"scheme": "spline"}"#).is_err());
        let p: ApfParams =
            serde_json::from_str(r#"{"follow": "path", "lookahead_m": 0.6}"#).expect("parse");
        assert_eq!((p.follow, p.lookahead_m), (Follow::Path, 0.6));
        assert!(serde_json::from_str::<ApfParams>(r#"{"follow": "carrot"}"#).is_err());
    }
}
