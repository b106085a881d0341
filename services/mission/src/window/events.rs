//! What the window's machine hears and what it asks the executive to do.

use roam_proto::controller::{ControllerStatus, Mission};
use roam_proto::planner::Plan;

use super::WindowEnd;
use crate::watch::Reason;

/// When an event happens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Now {
    /// The mission clock (the sim's when one runs), seconds.
    pub mission_s: f64,
    /// Wall seconds from any fixed origin: the lost-mission rule's clock, and the plan
    /// retries'.
    pub wall_s: f64,
    /// What a curious plan asked now costs on the mission clock, seconds (the executive
    /// measures it).
    pub planning_cost_s: f64,
}

/// What the executive hears.
#[derive(Debug, Clone, PartialEq)]
pub enum WindowEvent {
    /// Localization's estimate of the robot; a degraded one is ignored.
    Estimate {
        position: [f64; 2],
        peb_m: Option<f64>,
        degraded: bool,
    },
    /// The controller's status on this robot, on whichever mission.
    Status(ControllerStatus),
    /// Time passed.
    Tick,
    /// The planner's reply to the request in flight.
    PlanReply(Box<Plan>),
    /// The request in flight failed: no planner answered, or it refused.
    PlanFailed,
}

/// A plan to ask the planner for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanAsk {
    pub from: [f64; 2],
    pub to: [f64; 2],
    /// The driving budget t_exec, within the planner's range.
    pub t_exec_s: f64,
    /// A curious path (the executive's model); `false`: the shortest path.
    pub curious: bool,
}

/// What the executive does, in order.
#[derive(Debug, Clone, PartialEq)]
pub enum WindowAction {
    /// Send the robot this mission; it replaces the one the robot drives.
    Drive(Mission),
    /// Hold the robot where it is (a mission with no waypoints) while a slack replan is
    /// made.
    Hold(Mission),
    /// Ask the planner, then answer with [`WindowEvent::PlanReply`] or
    /// [`WindowEvent::PlanFailed`] before any other event.
    RequestPlan(PlanAsk),
    /// The window's first route, for a progress display.
    Planned {
        budget_s: f64,
        eta_s: f64,
        curious: bool,
    },
    /// A replan was sent.
    Replanned { reason: Reason },
    /// The robot reached the task's place; the time model's calibration learns from
    /// `drive`.
    Arrived { at_s: f64, drive: DrivenMission },
    /// The window is given up.
    GaveUp,
    /// The task was over before the window began.
    Skipped,
    /// The window is over; the machine does nothing more.
    Done(Box<WindowEnd>),
}

/// The mission that arrived, as the time model learns from it: the path it was planned
/// on, from where it was sent (the path following keeps the robot on it), and how long
/// driving it took.
#[derive(Debug, Clone, PartialEq)]
pub struct DrivenMission {
    pub path: Vec<[f64; 2]>,
    pub took_s: f64,
}
