//! What a window is measured by: its time (driven, waited, held, early), its
//! information (driven, planned, shortest, change seen) and how well its time model
//! predicted the drive. The drive's raw record is the in-process executive's
//! ([`crate::reproduce::executive::track`]).

use serde::Serialize;

/// One window of one variant's day.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WindowResult {
    pub window: usize,
    pub task: String,
    /// When the window began (the previous task's end, or the day's first estimate)
    /// and the task's start, mission seconds; `window_s` is the difference.
    pub began_s: f64,
    pub task_start_s: f64,
    pub window_s: f64,
    /// When the robot reached the task's place; `None`: it never did (given up).
    pub arrival_s: Option<f64>,
    /// Arrived after the task's start, or never.
    pub late: bool,
    /// From the first mission sent to the arrival, seconds (0 when it never arrived):
    /// the executive's "driving time", holds for slack replans included.
    pub driving_s: f64,
    /// `driving_s / window_s`: the share of the window driven.
    pub share: f64,
    /// From the window's beginning to its first mission: the robot waited for the plan.
    pub waited_for_plan_s: f64,
    /// Held by the controller's PEB guard, in all (the executive's count), seconds;
    /// how many holds it acted on and how many recoveries it sent.
    pub held_s: f64,
    pub holds: u32,
    pub recoveries: u32,
    /// The first plan's probability of arriving late, as its margin bounds it.
    pub late_probability: Option<f64>,
    /// Waiting at the task's place before its start (arrived early), seconds.
    pub early_s: Option<f64>,
    /// The driving budget of the first plan (t_exec), seconds.
    pub budget_s: f64,
    /// The first plan was curious (else the shortest path: curiosity did not fit).
    pub curious: bool,
    /// Cells of the first plan (1: the robot was to stay where it was).
    pub first_plan_cells: usize,
    /// Curious plans the window asked for (its GA runs).
    pub ga_plans: u32,
    /// Plans the planner refused (errors; the window machine went on as on a live
    /// refusal).
    pub refused_plans: u32,
    /// Paper 000's measure on the static map (distinct cells seen in the perception
    /// window): along the true driven path, along what the plans laid out (each
    /// replaced plan up to where the robot left it, the last one whole), and along the
    /// window's shortest path.
    pub driven_information: f64,
    pub planned_information: f64,
    pub shortest_information: f64,
    /// driven / planned; `None` when the plans promised nothing.
    pub driven_over_planned: Option<f64>,
    /// Cells that change during the day (the cart's) in the perception window of the
    /// true driven path.
    pub changing_cells_seen: f64,
    /// Mean PEB at the true positions along the drive (the field localization
    /// publishes; a cell without a fix counts 10 m), metres.
    pub peb_mean_m: Option<f64>,
    /// Steps the controller held the robot for its PEB.
    pub halted_steps: u64,
    /// RMS of the estimates' error along the drive (degraded estimates left out), metres.
    pub estimate_rms_m: Option<f64>,
    /// Each replan's reason, in order ([`roam_mission::watch::Reason::name`]).
    pub replans: Vec<&'static str>,
    /// The time model's prediction of the arrived mission.
    pub time_model: Option<TimeModelUse>,
}

/// How the window's time model predicted its last (arrived) mission.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TimeModelUse {
    pub v_lin: f64,
    pub v_ang: f64,
    /// Eq. 2 on the mission's plan (its Σd and Σθ), seconds.
    pub predicted_s: f64,
    /// From sending the mission to the arrival, seconds.
    pub took_s: f64,
    /// (predicted − took) / took: positive when the model is pessimistic.
    pub error: f64,
}
