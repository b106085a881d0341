//! One downtime window of the executive as a plain state machine: the bookkeeping and
//! the sequencing around the replan policy ([`crate::watch`]). No Zenoh, no tokio, no
//! clock of its own: the executive ([`crate::executive`]) feeds it [`WindowEvent`]s, each
//! with the time it happened ([`Now`]), and performs the [`WindowAction`]s it returns, in
//! order; the tests feed it events directly.
//!
//! The window, in order:
//! 1. **Begin** where the robot is. A task already over is skipped (the executive was
//!    down through it). The plan made for the window during the previous task is used
//!    when it starts within [`PREPLAN_FROM_M`] of the robot; otherwise a plan is asked
//!    for, and asked again every [`PLAN_RETRY_S`] (wall) after a failure, until the
//!    window is given up.
//! 2. **Drive**: the plan's route is sent as a mission and the watch starts. Every good
//!    estimate is recorded (the driven path, its PEB) and fed to the watch, as are the
//!    controller's statuses on the current mission and the ticks.
//! 3. **Replan** when the watch says so: one plan request from where the robot is, with
//!    the time left; slack holds the robot first. A curious request that fails is
//!    followed by one for the shortest path; when that fails too, nothing changes (a
//!    held robot is sent back on the path it had) and the watch decides again.
//! 4. **Arrive**: the time model's prediction is scored, the arrival margin learns, and
//!    the next window is planned from the task's place while the robot is at it (a plan
//!    that comes after the task ended is dropped); the window is done when the task
//!    ends. **Give up**: done at once.
//!
//! **One planner request per plan.** The executive asks every plan with the shortest
//! path as its fallback (`shortest: fallback`, [`roam_proto::planner::ShortestPathUse`]):
//! the reply carries the shortest path (the report's comparison, and the route when the
//! curious plan does not reach the goal within its budget), and a budget the shortest
//! path does not fit is answered with the shortest path rather than refused. A window
//! with no time left asks for the shortest path directly.
//!
//! While a request is in flight the machine only records estimates: the executive awaits
//! each request before it reads the next input, so the watch decides on a path the robot
//! has been given.

mod ending;
mod events;
mod handover;
mod routes;

pub use events::{DrivenMission, Now, PlanAsk, WindowAction, WindowEvent};
pub use handover::{Handover, WindowEnd, WindowOutcome};
pub use routes::{routes, PlannedAhead, Route};

use roam_planner::plan::MAX_T_EXEC_S;
use roam_proto::controller::{ControllerStatus, Mission, MissionState};

use crate::calibration::TimeModel;
use crate::information::InformationScale;
use crate::margin::ArrivalMargin;
use crate::path::{distance, mission_waypoints};
use crate::tasks::Task;
use crate::watch::{Decision, Reason, Status, Watch, WatchParams};

/// A window's plan made ahead is used when the robot sets off at most this far from
/// where it starts, metres.
pub const PREPLAN_FROM_M: f64 = 0.5;

/// Wall seconds between two requests for a window's first plan (or the next window's)
/// when none came: an outage costs downtime, not the mission.
pub const PLAN_RETRY_S: f64 = 1.0;

/// The least driving budget a request carries: the planner takes only positive ones. A
/// window with no time left asks for the shortest path, for which the budget only says
/// whether it fits.
const LEAST_T_EXEC_S: f64 = 1e-3;

/// The report's reason for a window given up before any plan came.
pub const NO_PLAN_REASON: &str = "no planner answered before the window was given up";

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
    pub give_up_after_s: f64,
    pub waypoint_spacing_m: f64,
    /// The map the report measures information on.
    pub scale: InformationScale<'a>,
}

/// The missions of a window, numbered on from the previous windows'.
#[derive(Debug, Clone)]
struct MissionIds {
    robot: String,
    tag: String,
    window: usize,
    sent: u64,
}

impl MissionIds {
    fn next(&mut self, waypoints: Vec<[f64; 2]>) -> Mission {
        self.sent += 1;
        Mission {
            robot: self.robot.clone(),
            id: format!(
                "{}-{}-w{}-m{}",
                self.robot, self.tag, self.window, self.sent
            ),
            waypoints,
        }
    }
}

/// The request in flight and what its reply is for.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Asked {
    FirstPlan {
        budget_s: f64,
    },
    Replan {
        reason: Reason,
        resend: bool,
        held: bool,
        ask: PlanAsk,
    },
    NextWindow {
        budget_s: f64,
    },
}

/// The robot on its way: what today's window loop kept in its locals.
#[derive(Debug, Clone)]
struct Drive {
    budget_s: f64,
    shortest: Vec<[f64; 2]>,
    /// Of the window's first route.
    planned_information: f64,
    /// Every route sent, in order.
    plans: Vec<Vec<[f64; 2]>>,
    /// The current route's waypoints (sent again after a slack hold that found no plan).
    waypoints: Vec<[f64; 2]>,
    /// The current mission's id: statuses on any other are not about this route.
    mission: String,
    first_sent_at_s: f64,
    sent_at_s: f64,
    /// The current route from where it was sent.
    path: Vec<[f64; 2]>,
    watch: Watch,
    reasons: Vec<String>,
}

#[derive(Debug, Clone)]
enum Phase {
    /// Waiting for the window's first plan, asked again at `retry_at_wall_s` after a
    /// failure.
    FirstPlan {
        retry_at_wall_s: Option<f64>,
    },
    Driving(Box<Drive>),
    /// Arrived; at the task until `leave_at_s`, planning the next window meanwhile.
    AtTask {
        outcome: Box<WindowOutcome>,
        leave_at_s: f64,
        retry_at_wall_s: Option<f64>,
    },
    Done,
}

/// One downtime window, from its first plan to the end of its task.
#[derive(Debug, Clone)]
pub struct DowntimeWindow<'a> {
    setup: WindowSetup<'a>,
    margin: ArrivalMargin,
    ids: MissionIds,
    /// The next window's plan, once made.
    planned_ahead: Option<PlannedAhead>,
    began_s: f64,
    /// The robot's last good estimate.
    here: [f64; 2],
    /// Where the window began, then every good estimate until the robot arrived.
    driven: Vec<[f64; 2]>,
    pebs: Vec<f64>,
    asked: Option<Asked>,
    phase: Phase,
}

impl<'a> DowntimeWindow<'a> {
    /// The window begins at `now` with what the previous one handed over; the actions
    /// are the first to perform.
    pub fn begin(
        setup: WindowSetup<'a>,
        handover: Handover,
        now: Now,
    ) -> (DowntimeWindow<'a>, Vec<WindowAction>) {
        let from = setup.from;
        let mut w = DowntimeWindow {
            ids: MissionIds {
                robot: setup.robot.clone(),
                tag: setup.mission_tag.clone(),
                window: setup.window,
                sent: handover.missions_sent,
            },
            margin: handover.margin,
            planned_ahead: None,
            began_s: now.mission_s,
            here: from,
            driven: vec![from],
            pebs: Vec::new(),
            asked: None,
            phase: Phase::FirstPlan {
                retry_at_wall_s: None,
            },
            setup,
        };
        let task = &w.setup.task;
        if now.mission_s >= task.start_s + task.duration_s {
            let done = w.finish(None);
            return (w, vec![WindowAction::Skipped, done]);
        }
        let window = w.setup.window;
        let ahead = handover
            .planned_ahead
            .filter(|p| p.window == window && distance(p.from, from) <= PREPLAN_FROM_M);
        let actions = match ahead {
            Some(p) => w.start_driving(p.route, p.shortest, p.budget_s, now),
            None => vec![w.ask_first_plan(now)],
        };
        (w, actions)
    }

    /// An event at `now`; the actions to perform, in order.
    pub fn handle(&mut self, event: WindowEvent, now: Now) -> Vec<WindowAction> {
        match event {
            WindowEvent::Estimate {
                position,
                peb_m,
                degraded,
            } => self.on_estimate(position, peb_m, degraded, now),
            WindowEvent::Status(status) => self.on_status(&status, now),
            WindowEvent::Tick => self.on_tick(now),
            WindowEvent::PlanReply(plan) => match (self.asked.take(), routes(*plan)) {
                (Some(asked), Some((route, shortest))) => self.on_plan(asked, route, shortest, now),
                (Some(asked), None) => self.on_plan_failed(asked, now),
                (None, _) => Vec::new(),
            },
            WindowEvent::PlanFailed => match self.asked.take() {
                Some(asked) => self.on_plan_failed(asked, now),
                None => Vec::new(),
            },
        }
    }

    /// The budget for a plan to a task starting at `task_start_s`, the robot leaving at
    /// `leave_at_s` at the earliest (now when `None`) and the plan costing what it costs.
    fn budget_to(&self, task_start_s: f64, leave_at_s: Option<f64>, now: Now) -> f64 {
        let earliest = now.mission_s + now.planning_cost_s;
        let time_left = task_start_s - leave_at_s.map_or(earliest, |at| at.max(earliest));
        self.margin.budget(time_left)
    }

    fn ask_first_plan(&mut self, now: Now) -> WindowAction {
        let budget_s = self.budget_to(self.setup.task.start_s, None, now);
        self.asked = Some(Asked::FirstPlan { budget_s });
        WindowAction::RequestPlan(ask(self.setup.from, self.setup.task.at, budget_s, true))
    }

    fn ask_next_window(&mut self, now: Now, leave_at_s: f64) -> Vec<WindowAction> {
        let Some(next) = &self.setup.next else {
            return Vec::new();
        };
        let (start_s, to) = (next.start_s, next.at);
        let budget_s = self.budget_to(start_s, Some(leave_at_s), now);
        self.asked = Some(Asked::NextWindow { budget_s });
        vec![WindowAction::RequestPlan(ask(
            self.setup.task.at,
            to,
            budget_s,
            true,
        ))]
    }

    fn start_driving(
        &mut self,
        route: Route,
        shortest: Vec<[f64; 2]>,
        budget_s: f64,
        now: Now,
    ) -> Vec<WindowAction> {
        let waypoints = mission_waypoints(&route.points, self.setup.waypoint_spacing_m);
        let mission = self.ids.next(waypoints.clone());
        let watch = Watch::new(
            self.setup.watch,
            self.setup.task.start_s,
            route.points.clone(),
            now.mission_s,
            now.wall_s,
        );
        let planned = WindowAction::Planned {
            budget_s,
            eta_s: route.t_eta_s,
            curious: route.curious,
        };
        self.phase = Phase::Driving(Box::new(Drive {
            budget_s,
            shortest,
            planned_information: self.setup.scale.of(&route.points),
            path: std::iter::once(self.setup.from)
                .chain(route.points.iter().copied())
                .collect(),
            plans: vec![route.points],
            waypoints,
            mission: mission.id.clone(),
            first_sent_at_s: now.mission_s,
            sent_at_s: now.mission_s,
            watch,
            reasons: Vec::new(),
        }));
        vec![planned, WindowAction::Drive(mission)]
    }

    fn on_estimate(
        &mut self,
        position: [f64; 2],
        peb_m: Option<f64>,
        degraded: bool,
        now: Now,
    ) -> Vec<WindowAction> {
        // At the task (or done) the drive is over: nothing more is recorded.
        let driving = matches!(self.phase, Phase::FirstPlan { .. } | Phase::Driving(_));
        if degraded || !driving {
            return Vec::new();
        }
        self.here = position;
        self.driven.push(position);
        self.pebs.extend(peb_m);
        match &mut self.phase {
            Phase::Driving(drive) if self.asked.is_none() => {
                let decision = drive.watch.on_estimate(position);
                self.decide(decision, now)
            }
            _ => Vec::new(),
        }
    }

    fn on_status(&mut self, s: &ControllerStatus, now: Now) -> Vec<WindowAction> {
        let Phase::Driving(drive) = &mut self.phase else {
            return Vec::new();
        };
        if self.asked.is_some() || s.mission.as_deref() != Some(drive.mission.as_str()) {
            return Vec::new();
        }
        let status = match s.state {
            MissionState::Completed => Status::Completed,
            MissionState::Stuck | MissionState::StepLimit => Status::Stuck,
            MissionState::Active => Status::Active {
                distance_left_m: s.distance_left_m.unwrap_or(0.0),
            },
            _ => Status::Other,
        };
        let decision =
            drive
                .watch
                .on_status(status, now.mission_s, now.wall_s, now.planning_cost_s);
        self.decide(decision, now)
    }

    fn on_tick(&mut self, now: Now) -> Vec<WindowAction> {
        if self.asked.is_some() {
            return Vec::new();
        }
        let due = |retry: &mut Option<f64>| {
            let due = retry.is_some_and(|at| now.wall_s >= at);
            if due {
                *retry = None;
            }
            due
        };
        match &mut self.phase {
            Phase::FirstPlan { retry_at_wall_s } => {
                if due(retry_at_wall_s) {
                    vec![self.ask_first_plan(now)]
                } else {
                    Vec::new()
                }
            }
            Phase::Driving(drive) => {
                let decision = drive.watch.on_tick(now.mission_s, now.wall_s);
                self.decide(decision, now)
            }
            Phase::AtTask {
                leave_at_s,
                retry_at_wall_s,
                ..
            } => {
                let leave_at_s = *leave_at_s;
                if now.mission_s < leave_at_s && due(retry_at_wall_s) {
                    self.ask_next_window(now, leave_at_s)
                } else {
                    self.finish_at_task_end(now)
                }
            }
            Phase::Done => Vec::new(),
        }
    }

    fn decide(&mut self, decision: Decision, now: Now) -> Vec<WindowAction> {
        match decision {
            Decision::Keep => Vec::new(),
            Decision::Arrived { at_s } => self.arrive(at_s, now),
            Decision::GiveUp => self.give_up(),
            Decision::Replan {
                reason,
                curious,
                resend,
            } => self.replan(reason, curious, resend, now),
        }
    }

    fn replan(
        &mut self,
        reason: Reason,
        curious: bool,
        resend: bool,
        now: Now,
    ) -> Vec<WindowAction> {
        let budget_s = self.budget_to(self.setup.task.start_s, None, now);
        let ask = ask(self.here, self.setup.task.at, budget_s, curious);
        let Phase::Driving(drive) = &mut self.phase else {
            return Vec::new();
        };
        let mut actions = Vec::new();
        // Slack pays for the robot waiting while it plans, so the new route starts where
        // the robot is rather than where it was.
        let held = reason == Reason::Slack;
        if held {
            let hold = self.ids.next(Vec::new());
            drive.mission = hold.id.clone();
            actions.push(WindowAction::Hold(hold));
        }
        self.asked = Some(Asked::Replan {
            reason,
            resend,
            held,
            ask,
        });
        actions.push(WindowAction::RequestPlan(ask));
        actions
    }

    fn on_plan(
        &mut self,
        asked: Asked,
        route: Route,
        shortest: Vec<[f64; 2]>,
        now: Now,
    ) -> Vec<WindowAction> {
        match asked {
            Asked::FirstPlan { budget_s } => {
                if !matches!(self.phase, Phase::FirstPlan { .. }) {
                    return Vec::new();
                }
                self.start_driving(route, shortest, budget_s, now)
            }
            Asked::Replan {
                reason,
                resend,
                ask,
                ..
            } => {
                let Phase::Driving(drive) = &mut self.phase else {
                    return Vec::new();
                };
                let path: Vec<[f64; 2]> = std::iter::once(ask.from)
                    .chain(route.points.iter().copied())
                    .collect();
                drive.reasons.push(reason.as_str().to_owned());
                drive
                    .watch
                    .replanned(path.clone(), resend, now.mission_s, now.wall_s);
                drive.waypoints = mission_waypoints(&route.points, self.setup.waypoint_spacing_m);
                drive.plans.push(route.points);
                let mission = self.ids.next(drive.waypoints.clone());
                drive.mission = mission.id.clone();
                drive.sent_at_s = now.mission_s;
                drive.path = path;
                vec![
                    WindowAction::Replanned { reason },
                    WindowAction::Drive(mission),
                ]
            }
            Asked::NextWindow { budget_s } => {
                let Phase::AtTask { leave_at_s, .. } = self.phase else {
                    return Vec::new();
                };
                // A plan for a window that has begun would start from a place the robot
                // may have left: dropped.
                if now.mission_s <= leave_at_s {
                    self.planned_ahead = Some(PlannedAhead {
                        window: self.setup.window + 1,
                        from: self.setup.task.at,
                        route,
                        shortest,
                        budget_s,
                    });
                }
                self.finish_at_task_end(now)
            }
        }
    }

    fn on_plan_failed(&mut self, asked: Asked, now: Now) -> Vec<WindowAction> {
        let task = &self.setup.task;
        match asked {
            Asked::FirstPlan { .. } => {
                if now.mission_s > task.start_s + self.setup.give_up_after_s {
                    return self.give_up_without_a_plan();
                }
                self.phase = Phase::FirstPlan {
                    retry_at_wall_s: Some(now.wall_s + PLAN_RETRY_S),
                };
                Vec::new()
            }
            // A curious plan that fails (busy, an outage) leaves the shortest way.
            Asked::Replan {
                reason,
                resend,
                held,
                ask,
            } if ask.curious => {
                let ask = PlanAsk {
                    curious: false,
                    ..ask
                };
                self.asked = Some(Asked::Replan {
                    reason,
                    resend,
                    held,
                    ask,
                });
                vec![WindowAction::RequestPlan(ask)]
            }
            Asked::Replan { held, .. } => {
                let Phase::Driving(drive) = &mut self.phase else {
                    return Vec::new();
                };
                if !held {
                    return Vec::new();
                }
                // Held for nothing: back on the path it had.
                let mission = self.ids.next(drive.waypoints.clone());
                drive.mission = mission.id.clone();
                vec![WindowAction::Drive(mission)]
            }
            Asked::NextWindow { .. } => {
                let Phase::AtTask {
                    leave_at_s,
                    retry_at_wall_s,
                    ..
                } = &mut self.phase
                else {
                    return Vec::new();
                };
                let next_given_up = self
                    .setup
                    .next
                    .as_ref()
                    .is_none_or(|n| now.mission_s > n.start_s + self.setup.give_up_after_s);
                if now.mission_s < *leave_at_s && !next_given_up {
                    *retry_at_wall_s = Some(now.wall_s + PLAN_RETRY_S);
                    return Vec::new();
                }
                self.finish_at_task_end(now)
            }
        }
    }
}

/// A request for `budget_s`: curious only when there is time to be curious in, and the
/// budget within the planner's range (the report keeps the budget as computed).
fn ask(from: [f64; 2], to: [f64; 2], budget_s: f64, curious: bool) -> PlanAsk {
    PlanAsk {
        from,
        to,
        t_exec_s: budget_s.clamp(LEAST_T_EXEC_S, MAX_T_EXEC_S),
        curious: curious && budget_s > 0.0,
    }
}

#[cfg(test)]
mod tests;
