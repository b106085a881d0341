//! What a window is given: its task, the executive's settings and rules, and the fixed
//! distances, periods and limits of its sequencing.

use crate::calibration::TimeModel;
use crate::config::ExecutiveConfig;
use crate::information::InformationScale;
use crate::tasks::Task;
use crate::watch::WatchParams;

/// A window's plan made ahead is used when the robot sets off at most this far from
/// where it starts, metres.
pub const PREPLAN_FROM_M: f64 = 0.5;

/// A plan made ahead is used when its window begins at most this long after the time
/// it assumed the robot would set off, mission seconds (a sim step and a bit).
pub const PREPLAN_LATE_S: f64 = 1.0;

/// Wall seconds between two requests for a window's first plan (or the next window's)
/// after the first failure: an outage costs downtime, not the mission.
pub const PLAN_RETRY_S: f64 = 1.0;

/// The longest wait between two such requests, wall seconds: the wait doubles with each
/// failure in a row ([`plan_retry_after_s`]) up to this.
pub const MAX_PLAN_RETRY_S: f64 = 8.0;

/// Wall seconds to wait before asking again after `failures` failed requests in a row:
/// [`PLAN_RETRY_S`] doubled for each failure after the first, at most
/// [`MAX_PLAN_RETRY_S`]. Why back off: a refusal that retrying cannot cure soon (the
/// next task's place inside what the fleet saw occupied, a budget too short for the
/// path) was asked again every second until the window's end, 409 times in one
/// warehouse window; an outage or a busy planner still gets its first retries within
/// seconds.
pub fn plan_retry_after_s(failures: u32) -> f64 {
    let doublings = failures.saturating_sub(1).min(16);
    (PLAN_RETRY_S * f64::from(1u32 << doublings)).min(MAX_PLAN_RETRY_S)
}

/// Failed first-plan requests after which the robot drives the window's own fastest
/// path rather than wait on.
pub const FALLBACK_AFTER_FAILURES: u32 = 2;

/// Mission seconds between two last-safe-moment checks at most.
pub const SAFE_CHECK_S: f64 = 1.0;

/// Recoveries from PEB holds one window sends at most: a robot held again after them
/// stays held (and the window is given up in time), rather than shuttle.
pub const MAX_RECOVERIES: u32 = 3;

/// A recovery drives back along the robot's track at least this far, metres, past its
/// last fix: where the fix is lost, localization's estimate freezes at the last fix, so
/// a way back to that point alone would be done before the robot moved.
pub const RECOVERY_BACK_M: f64 = 1.5;

/// The least deadline a plan request carries, wall seconds.
pub const MIN_DEADLINE_S: f64 = 0.05;

/// The least driving budget a request carries: the planner takes only positive ones. A
/// window with no time left asks for the shortest path, for which the budget only says
/// whether it fits.
pub(super) const LEAST_T_EXEC_S: f64 = 1e-3;

/// The report's reason (a token, as [`crate::watch::Reason::name`]) for a window given
/// up before any plan came: no planner answered before the window was given up.
pub const NO_PLAN_REASON: &str = "no_plan";

/// The executive's rules a window follows (from [`ExecutiveConfig`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowRules {
    /// Ask for curious plans at all (`false`: the fastest path in every window).
    pub curious: bool,
    pub plan_ahead: bool,
    pub recover: bool,
    pub hold_patience_s: f64,
    /// An estimate with a PEB at most this is a fix a recovery may go back to, metres.
    pub fix_peb_m: f64,
    pub replan_time_share: f64,
    /// The configured deadline, wall seconds.
    pub plan_deadline_s: f64,
    /// Without a plan made ahead, set off on the fastest path while the first curious
    /// plan is made (module doc, step 1).
    pub set_off_at_once: bool,
}

impl WindowRules {
    /// The rules `config` sets.
    pub fn of(config: &ExecutiveConfig) -> WindowRules {
        WindowRules {
            curious: config.curious(),
            plan_ahead: config.plan_ahead,
            recover: config.recover,
            hold_patience_s: config.hold_patience_s,
            fix_peb_m: config.fix_peb_m,
            replan_time_share: config.replan_time_share,
            plan_deadline_s: config.plan_deadline_s,
            set_off_at_once: config.set_off_at_once,
        }
    }
}

/// What a window is about and the executive's settings for it.
#[derive(Debug, Clone)]
pub struct WindowSetup<'a> {
    /// 0 for the first window.
    pub window: usize,
    pub task: Task,
    /// The task after this one, planned for during this one.
    pub next: Option<Task>,
    pub robot: String,
    /// The executive's own tag in its mission ids, so a restarted executive never
    /// reuses its predecessor's.
    pub mission_tag: String,
    /// Where the robot is as the window begins.
    pub from: [f64; 2],
    /// The time model the window's plans are made with (paper 000 Eq. 2).
    pub time_model: TimeModel,
    pub watch: WatchParams,
    pub rules: WindowRules,
    pub give_up_after_s: f64,
    pub waypoint_spacing_m: f64,
    /// The map the report measures information on, and the window's own fastest paths
    /// are found on.
    pub scale: InformationScale<'a>,
}
