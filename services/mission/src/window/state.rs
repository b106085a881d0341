//! What a window holds as it runs: its phase, the drive under way, its missions and its
//! plan requests in flight.

use roam_proto::controller::Mission;
use roam_proto::mission::AskReport;

use crate::margin::ArrivalMargin;
use crate::watch::{Reason, Replanned, Watch};

use super::events::PlanAsk;
use super::handover::WindowOutcome;
use super::routes::PlannedAhead;
use super::setup::WindowSetup;

/// The missions of a window, numbered on from the previous windows'.
#[derive(Debug, Clone)]
pub(crate) struct MissionIds {
    pub(crate) robot: String,
    pub(crate) tag: String,
    pub(crate) window: usize,
    pub(crate) sent: u64,
}

impl MissionIds {
    pub(crate) fn next(&mut self, waypoints: Vec<[f64; 2]>, recovery: bool) -> Mission {
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
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum DriveAsk {
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
pub(crate) enum Follows {
    /// A replan, counted as `Replanned` says.
    Replan(Replanned),
    /// Straight to the task, curious no more.
    Straight,
}

/// The next window's request in flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AheadAsk {
    pub(crate) budget_s: f64,
    pub(crate) time_left_s: f64,
    pub(crate) leave_at_s: f64,
}

/// The robot on its way.
#[derive(Debug, Clone)]
pub(crate) struct Drive {
    pub(crate) budget_s: f64,
    pub(crate) shortest: Vec<[f64; 2]>,
    /// Of the window's first route.
    pub(crate) planned_information: f64,
    pub(crate) late_probability: f64,
    /// Every route sent, in order.
    pub(crate) plans: Vec<Vec<[f64; 2]>>,
    /// The current route's waypoints.
    pub(crate) waypoints: Vec<[f64; 2]>,
    /// The current mission's id: statuses on any other are not about this route.
    pub(crate) mission: String,
    /// The current route is a curious one (the last-safe-moment rule watches it).
    pub(crate) route_curious: bool,
    pub(crate) first_sent_at_s: f64,
    pub(crate) sent_at_s: f64,
    /// The current route from where it was sent.
    pub(crate) path: Vec<[f64; 2]>,
    pub(crate) watch: Watch,
    pub(crate) reasons: Vec<String>,
    pub(crate) safe_checked_at_s: f64,
    /// The current mission is a recovery back to the last fix.
    pub(crate) recovering: bool,
    /// Since when the PEB guard holds the robot, if it does.
    pub(crate) held_since_s: Option<f64>,
    pub(crate) holds: u32,
    pub(crate) held_s: f64,
    pub(crate) recoveries: u32,
}

#[derive(Debug, Clone)]
pub(crate) enum Phase {
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
    pub(crate) setup: WindowSetup<'a>,
    pub(crate) margin: ArrivalMargin,
    pub(crate) ids: MissionIds,
    pub(crate) asks_made: u64,
    /// The next window's plan, once made.
    pub(crate) planned_ahead: Option<PlannedAhead>,
    pub(crate) began_s: f64,
    /// The robot's last good estimate.
    pub(crate) here: [f64; 2],
    /// The previous window's track end (`carried` points, for recoveries: see
    /// [`Handover::track`]), then where this window began and every good estimate
    /// until the robot arrived.
    pub(crate) driven: Vec<[f64; 2]>,
    pub(crate) carried: usize,
    /// The index in `driven` of the last estimate with a fix.
    pub(crate) last_fix: usize,
    /// The track handed to the next window, kept when the drive's outcome is made.
    pub(crate) track_out: Option<(Vec<[f64; 2]>, usize)>,
    pub(crate) pebs: Vec<f64>,
    pub(crate) drive_ask: Option<(u64, DriveAsk)>,
    pub(crate) ahead_ask: Option<(u64, AheadAsk)>,
    /// The window's requests, for its report (at most [`MAX_REPORTED_ASKS`]), and how
    /// many it made.
    pub(crate) asks: Vec<AskReport>,
    pub(crate) asks_in_window: u32,
    pub(crate) phase: Phase,
}
