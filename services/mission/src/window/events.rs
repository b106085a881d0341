//! What the window's machine hears and what it asks the executive to do.

use roam_proto::controller::{ControllerStatus, Mission};
use roam_proto::planner::Plan;

use super::handover::WindowEnd;
use crate::calibration::{path_measure, Calibration};
use crate::watch::Reason;

/// When an event happens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Now {
    /// The mission clock (the sim's when one runs), seconds.
    pub mission_s: f64,
    /// Wall seconds from any fixed origin: the lost-mission rule's clock, and the plan
    /// retries'.
    pub wall_s: f64,
    /// What a curious plan asked now is expected to cost on the mission clock, seconds
    /// (the executive measures it, or its config fixes it).
    pub planning_cost_s: f64,
    /// The same for a replan seeded with the route the robot drives (it runs
    /// `replan_generations`, far fewer: tens of milliseconds where a plan takes
    /// hundreds).
    pub replan_cost_s: f64,
    /// Mission seconds per wall second (the sim's real-time factor; 1 on wall time).
    pub clock_rate: f64,
}

/// What the executive hears.
#[derive(Debug, Clone, PartialEq)]
pub enum WindowEvent {
    /// Localization's estimate of the robot; a degraded one is ignored. `time_s` is
    /// its own time on the mission clock (the step it was made at), not when it was
    /// heard: drives are timed by it (`drove.rs`), so that the live executive, which
    /// hears it late by a varying lag, and the batch, which hears it at once, time
    /// them alike. Not a number when the estimate's time is not on the mission clock
    /// (a wall-clock mission): then the time it was heard.
    Estimate {
        position: [f64; 2],
        peb_m: Option<f64>,
        degraded: bool,
        time_s: f64,
    },
    /// The controller's status on this robot, on whichever mission.
    Status(ControllerStatus),
    /// Time passed.
    Tick,
    /// The planner's reply to request `id`.
    PlanReply { id: u64, plan: Box<Plan> },
    /// Request `id` failed: no planner answered, or it refused.
    PlanFailed { id: u64 },
    /// What the fleet believes occupied where the static map is free changed: the
    /// route left is checked against it (`blocked.rs`). Shared, since a fleet's
    /// robots hear the same set.
    MapChanged(std::sync::Arc<crate::seen::SeenObstacles>),
}

/// A plan to ask the planner for.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanAsk {
    /// Names the request's reply ([`WindowEvent::PlanReply`]); unique over the day.
    pub id: u64,
    pub from: [f64; 2],
    pub to: [f64; 2],
    /// The driving budget t_exec, within the planner's range.
    pub t_exec_s: f64,
    /// The planner's deadline, wall seconds: the configured one, cut to what the time
    /// left can afford at the clock's rate.
    pub deadline_s: f64,
    /// A curious path (the executive's model); `false`: the shortest path.
    pub curious: bool,
    /// A replan's warm start: the route the robot drives, from `from` on (empty for a
    /// window's first plan); the request's `seed_route`.
    pub seed_route: Vec<[f64; 2]>,
}

/// What the executive does, in order.
#[derive(Debug, Clone, PartialEq)]
pub enum WindowAction {
    /// Send the robot this mission; it replaces the one the robot drives.
    Drive(Mission),
    /// Ask the planner, without waiting: its answer comes back as
    /// [`WindowEvent::PlanReply`] or [`WindowEvent::PlanFailed`] with the ask's id,
    /// whenever it comes. At most two are in flight (the drive's, the next window's).
    RequestPlan(PlanAsk),
    /// Forget request `id`: its answer, if it comes, is not wanted (the executive may
    /// cancel it).
    Forget(u64),
    /// The window's first route, for a progress display.
    Planned {
        budget_s: f64,
        eta_s: f64,
        curious: bool,
        late_probability: f64,
    },
    /// A replan was sent (or the robot sent straight, or recovered).
    Replanned { reason: Reason },
    /// The PEB guard held the robot too long: it is driven back to where it had a fix.
    Recovering { held_s: f64 },
    /// The robot reached the task's place; the time model's calibration learns from
    /// `drives`: the parts driven of the window's missions that replans replaced, then
    /// the one that arrived, up to the robot's last estimate (`drove.rs`). Learned at
    /// the arrival, not as they are driven: the window plans, checks and replans with
    /// one time model.
    Arrived {
        at_s: f64,
        drives: Vec<DrivenMission>,
    },
    /// The window is given up.
    GaveUp,
    /// The task was over before the window began.
    Skipped,
    /// The window is over; the machine does nothing more.
    Done(Box<WindowEnd>),
}

/// A mission driven, as the time model learns from it: the path it was planned on,
/// from where it was sent (the path following keeps the robot on it) to where it
/// arrived or was replaced, and how long driving that took.
#[derive(Debug, Clone, PartialEq)]
pub struct DrivenMission {
    pub path: Vec<[f64; 2]>,
    pub took_s: f64,
}

impl DrivenMission {
    /// Adds this drive to `calibration` in the planner's own terms (its Σd and Σθ as
    /// Eq. 2 counts them on the cells, and how long it took); false when the drive is
    /// not usable (see [`Calibration::add_planned`]).
    pub fn teach(&self, calibration: &mut Calibration) -> bool {
        let (d, theta) = path_measure(&self.path);
        calibration.add_planned(d, theta, self.took_s)
    }
}
