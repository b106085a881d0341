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
    /// Why each replan happened, in order.
    pub replan_reasons: Vec<String>,
    /// The time model (paper 000 Eq. 2) the window was planned with, and how well it
    /// predicted what the robot drove.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_model: Option<TimeModelReport>,
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
