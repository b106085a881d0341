//! What a window holds as it runs: its phase, the drive under way, its missions and its
//! plan requests in flight.

use roam_proto::controller::Mission;
use roam_proto::mission::AskReport;

use crate::margin::ArrivalMargin;
use crate::watch::{Reason, Replanned, Watch};

use super::events::{DrivenMission, PlanAsk};
use super::handover::WindowOutcome;
use super::routes::PlannedAhead;
use super::setup::WindowSetup;

/// The missions of a window, numbered on from the previous windows'.
#[derive(Debug, Clone)]
pub(super) struct MissionIds {
    pub(super) robot: String,
    pub(super) tag: String,
    pub(super) window: usize,
    pub(super) sent: u64,
}

impl MissionIds {
    pub(super) fn next(&mut self, waypoints: Vec<[f64; 2]>, recovery: bool) -> Mission {
        self.sent += 1;
        Mission {
            after_step: None,
            robot: self.robot.clone(),
            id: format!(
                "{}-{}-w{}-m{}",
                self.robot, self.tag, self.window, self.sent
            ),
            waypoints,
            recovery,
        }
    }
}

/// The drive's request in flight and what its reply is for.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum DriveAsk {
    FirstPlan {
        budget_s: f64,
        time_left_s: f64,
    },
    Replan {
        reason: Reason,
        resend: bool,
        ask: PlanAsk,
    },
}

/// How the watch takes a new route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Follows {
    /// A replan, counted as `Replanned` says.
    Replan(Replanned),
    /// Straight to the task, curious no more.
    Straight,
}

/// The next window's request in flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct AheadAsk {
    pub(super) budget_s: f64,
    pub(super) time_left_s: f64,
    pub(super) leave_at_s: f64,
}

/// The robot on its way.
#[derive(Debug, Clone)]
pub(super) struct Drive {
    pub(super) budget_s: f64,
    pub(super) shortest: Vec<[f64; 2]>,
    /// Of the window's first route.
    pub(super) planned_information: f64,
    pub(super) late_probability: f64,
    /// Every route sent, in order.
    pub(super) plans: Vec<Vec<[f64; 2]>>,
    /// The current route's waypoints.
    pub(super) waypoints: Vec<[f64; 2]>,
    /// The current mission's id: statuses on any other are not about this route.
    pub(super) mission: String,
    /// The current route is a curious one (the last-safe-moment rule watches it).
    pub(super) route_curious: bool,
    pub(super) first_sent_at_s: f64,
    pub(super) sent_at_s: f64,
    /// The parts driven of the routes replans replaced, learned at the arrival.
    pub(super) drives: Vec<DrivenMission>,
    /// Where the robot was when the current route was sent, and when it was there
    /// (its last estimate's time; the route's time if it stood still).
    pub(super) sent_here: ([f64; 2], f64),
    /// The current route from where it was sent.
    pub(super) path: Vec<[f64; 2]>,
    pub(super) watch: Watch,
    pub(super) reasons: Vec<String>,
    pub(super) safe_checked_at_s: f64,
    /// The current mission is a recovery back to the last fix.
    pub(super) recovering: bool,
    /// Since when the PEB guard holds the robot, if it does.
    pub(super) held_since_s: Option<f64>,
    pub(super) holds: u32,
    /// `holds` when the current route was sent: more now, and it was held on.
    pub(super) sent_holds: u32,
    /// The current route was sent so that its drive can be timed (`drove.rs`).
    pub(super) route_teaches: bool,
    pub(super) held_s: f64,
    pub(super) recoveries: u32,
}

#[derive(Debug, Clone)]
pub(super) enum Phase {
    /// Waiting for the window's first plan, asked again at `retry_at_wall_s` after a
    /// failure.
    FirstPlan {
        retry_at_wall_s: Option<f64>,
        failures: u32,
    },
    Driving(Box<Drive>),
    /// Arrived; at the task until `leave_at_s`; the next window's plan asked again at
    /// `retry_at_wall_s` after `failures` failures in a row.
    AtTask {
        outcome: Box<WindowOutcome>,
        leave_at_s: f64,
        retry_at_wall_s: Option<f64>,
        failures: u32,
    },
    Done,
}

/// One downtime window, from its first plan to the end of its task.
#[derive(Debug, Clone)]
pub struct DowntimeWindow<'a> {
    pub(super) setup: WindowSetup<'a>,
    pub(super) margin: ArrivalMargin,
    pub(super) ids: MissionIds,
    pub(super) asks_made: u64,
    /// The next window's plan, once made.
    pub(super) planned_ahead: Option<PlannedAhead>,
    pub(super) began_s: f64,
    /// The robot's last good estimate, and when it was heard (mission seconds).
    pub(super) here: [f64; 2],
    pub(super) here_at_s: f64,
    /// The previous window's track end (`carried` points, for recoveries: see
    /// [`Handover::track`]), then where this window began and every good estimate
    /// until the robot arrived.
    pub(super) driven: Vec<[f64; 2]>,
    pub(super) carried: usize,
    /// The index in `driven` of the last estimate with a fix.
    pub(super) last_fix: usize,
    /// The track handed to the next window, kept when the drive's outcome is made.
    pub(super) track_out: Option<(Vec<[f64; 2]>, usize)>,
    pub(super) pebs: Vec<f64>,
    pub(super) drive_ask: Option<(u64, DriveAsk)>,
    pub(super) ahead_ask: Option<(u64, AheadAsk)>,
    /// The window's requests, for its report (at most [`MAX_REPORTED_ASKS`]), and how
    /// many it made.
    pub(super) asks: Vec<AskReport>,
    pub(super) asks_in_window: u32,
    pub(super) phase: Phase,
    /// The last set of believed obstacles heard (`blocked.rs`), and whether the route
    /// has been checked against it.
    pub(super) obstacles: Option<std::sync::Arc<crate::seen::SeenObstacles>>,
    pub(super) obstacles_unchecked: bool,
    /// The planning world with the cells near those obstacles blocked: the window's own
    /// fastest paths go round them (`None`: the static world).
    pub(super) seen_world: Option<roam_planner::world::World>,
}
