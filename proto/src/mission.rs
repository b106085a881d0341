//! Messages of the mission executive: what a robot did with one downtime window.

use serde::{Deserialize, Serialize};

use crate::codec::Message;

/// One downtime window's outcome, on `<root>/robot/<id>/mission_report` when the window
/// ends (the robot reached the task, or gave up).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindowReport {
    pub robot: String,
    /// The task the window leads to.
    pub task: String,
    /// 0 for the first window.
    pub window: usize,
    /// When the window began and when the task starts, sim seconds.
    pub began_s: f64,
    pub task_start_s: f64,
    /// When the robot reached the task's place; `None` if it did not.
    pub arrival_s: Option<f64>,
    /// Reached no later than the task's start.
    pub on_time: bool,
    /// The driving budget the planner was given (paper 000's t_exec), seconds.
    pub budget_s: f64,
    /// The information of the distinct cells seen along the planned curious path, along
    /// the path the robot drove (from its estimates), and along the shortest path of the
    /// same window (paper 000's information map, perception window d).
    pub planned_information: f64,
    pub driven_information: f64,
    pub shortest_information: f64,
    /// The mean PEB of the window's estimates (bounded ones), metres.
    pub peb_mean_m: Option<f64>,
    /// Plans after the first (blocked, pushed off the path, ETA slipping).
    pub replans: u32,
    /// Why each replan happened, in order, as tokens a program can branch on:
    /// `silent`, `stuck`, `late`, `off_path`, `slack`, `behind`, `last_safe_moment`,
    /// `recovered`, `no_planner`, `set_off` (`roam_mission::watch::Reason::name`), and
    /// `no_plan` alone for a window given up before any plan came.
    pub replan_reasons: Vec<String>,
    /// The time model (paper 000 Eq. 2) the window was planned with, and how well it
    /// predicted what the robot drove.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_model: Option<TimeModelReport>,
    /// The probability that the window's first plan arrives late, as the arrival margin
    /// bounds it from the robot's own prediction errors (`roam_mission::margin`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub late_probability: Option<f64>,
    /// Times the controller's PEB guard held the robot long enough for the executive to
    /// act, the seconds it was held in all, and the recoveries sent (back along the
    /// driven path to where it had a fix).
    #[serde(default)]
    pub holds: u32,
    #[serde(default)]
    pub held_s: f64,
    #[serde(default)]
    pub recoveries: u32,
    /// The window's plan requests in order (at most [`MAX_REPORTED_ASKS`]; `asks_made`
    /// counts them all).
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "crate::bounded::vec::<_, MAX_REPORTED_ASKS, _>"
    )]
    pub asks: Vec<AskReport>,
    #[serde(default)]
    pub asks_made: u32,
}

/// The most plan requests a window report lists.
pub const MAX_REPORTED_ASKS: usize = 64;

/// One plan request of a window, as its report lists it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AskReport {
    /// When it was asked, mission seconds.
    pub at_s: f64,
    pub from: [f64; 2],
    pub t_exec_s: f64,
    pub curious: bool,
    /// For the next window (made ahead), not this one's drive.
    pub ahead: bool,
}

/// A window's time model and its prediction error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeModelReport {
    /// Seconds per metre and per radian the window's plans were made with.
    pub v_lin: f64,
    pub v_ang: f64,
    /// What the model predicted for the distance and turning the robot drove, and how
    /// long that driving took (stops left out), seconds.
    pub predicted_s: f64,
    pub driving_s: f64,
    /// `driving_s` over the window (the task's start minus the window's beginning): the
    /// share of the downtime the robot spent driving.
    pub driven_share: f64,
}

impl Message for WindowReport {
    const KIND: &'static str = "window_report";
}

/// What the mission executive is doing, on `<root>/robot/<id>/executive` after each
/// estimate, controller status and plan reply it handled: for an operator's display,
/// and for a lock-step driver, which steps the sim once the executive has heard the
/// step and has no plan in flight.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExecutiveStatus {
    pub robot: String,
    /// The window it is in (0 for the first).
    pub window: usize,
    /// The sim step of the last estimate it handled, and of the estimate the
    /// controller's last status it handled answered (`None` before the first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimate_step: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status_step: Option<u64>,
    /// Plan requests it waits on.
    pub plans_in_flight: u32,
}

impl Message for ExecutiveStatus {
    const KIND: &'static str = "executive_status";
}
