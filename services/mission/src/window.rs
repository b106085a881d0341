//! One downtime window of the executive as a plain state machine: the bookkeeping and
//! the sequencing around the replan policy ([`crate::watch`]). No Zenoh, no tokio, no
//! clock of its own: the live executive ([`crate::executive`]) and the batch of days
//! (`roam_experiments::reproduce::mission::days`) feed it [`WindowEvent`]s, each with
//! the time it happened ([`Now`]), and perform the [`WindowAction`]s it returns, in
//! order; the tests feed it events directly. This is the one window loop roam has.
//!
//! The window, in order:
//! 1. **Begin** where the robot is. A task already over is skipped (the executive was
//!    down through it). The plan made for the window ahead of time is used when it
//!    starts within [`PREPLAN_FROM_M`] of the robot and the window begins when that
//!    plan assumed. Otherwise, with `set_off_at_once`, the robot sets off at once on the
//!    fastest path the window computes itself and the curious plan is asked from where
//!    the robot will be when it comes (the window's time is not spent waiting for the
//!    planner); if that plan fails the robot drives on and the slack rule may bring
//!    curiosity back. Without it (or with no fastest path), a plan is asked for, and
//!    asked again every [`PLAN_RETRY_S`] (wall) after a failure. After
//!    [`FALLBACK_AFTER_FAILURES`] failures the robot drives the fastest path the window
//!    computes itself (no planner: degrade, don't stop) and curiosity comes back
//!    through the slack rule.
//! 2. **Drive**: the plan's route is sent as a mission and the watch starts. Every good
//!    estimate is recorded (the driven path, its PEB, the last point with a fix) and
//!    fed to the watch, as are the controller's statuses on the current mission and
//!    the ticks. With `plan_ahead` the next window's plan is asked for at once, from
//!    this task's place, so that it is ready when this task ends.
//! 3. **Replan** when the watch says so: one plan request with the time left. The
//!    robot drives on while the plan is made: a slack or behind replan starts where the
//!    robot will be when the plan comes (the point that far along its route), so
//!    planning costs the window nothing. A curious request that fails is followed by
//!    one for the shortest path; when that fails too, the window's own fastest path.
//! 4. **The last safe moment.** At most every [`SAFE_CHECK_S`] on a curious route, the
//!    window computes the fastest path from where the robot is; when the budget the
//!    arrival margin leaves of the time left, less twice the check's period, no
//!    longer exceeds that path's time, the robot goes straight, at once, without the
//!    planner, and never curious again in the window (until the next check the
//!    curious route may lead the robot away from the task, and back costs as much). A
//!    late ETA does the same.
//! 5. **Holds.** When the controller's PEB guard holds the robot for
//!    `hold_patience_s`, the window sends a recovery mission back along the robot's own
//!    track to the last estimate with a fix (PEB at most `fix_peb_m`) and at least
//!    [`RECOVERY_BACK_M`] back (where the fix is lost the estimate freezes), which the guard
//!    lets through, then sends it straight to the task from there (a curious route would
//!    lead back into the gap). At most [`MAX_RECOVERIES`] a window.
//! 6. **Arrive**: the time model's prediction is scored, the arrival margin learns, and
//!    the window is done when the task ends (and the next window's plan is in, or
//!    failed). **Give up**: done at once.
//!
//! **Plan budgets and deadlines.** Each plan's deadline is the configured one cut to
//! `replan_time_share` of the time left at the clock's rate, and its budget is what the
//! arrival margin ([`crate::margin`]) leaves of the time to the task after the plan's
//! expected cost: the plan's probability of arriving late is bounded, and reported with
//! it. One planner request per plan (`shortest: fallback`): the reply carries the
//! shortest path, and a budget it does not fit is answered with it.

mod asks;
mod ending;
mod events;
mod handover;
mod heard;
mod holds;
mod replies;
mod routes;
mod straight;

pub use events::{DrivenMission, Now, PlanAsk, WindowAction, WindowEvent};
pub use handover::{Handover, WindowEnd, WindowOutcome};
pub use routes::{routes, PlannedAhead, Route};

use roam_proto::controller::Mission;
use roam_proto::mission::AskReport;

use crate::calibration::{path_measure, TimeModel};
use crate::config::ExecutiveConfig;
use crate::information::InformationScale;
use crate::margin::ArrivalMargin;
use crate::path::{distance, mission_waypoints};
use crate::tasks::Task;
use crate::watch::{Decision, Reason, Replanned, Watch, WatchParams};

/// A window's plan made ahead is used when the robot sets off at most this far from
/// where it starts, metres.
pub const PREPLAN_FROM_M: f64 = 0.5;

/// A plan made ahead is used when its window begins at most this long after the time
/// it assumed the robot would set off, mission seconds (a sim step and a bit).
pub const PREPLAN_LATE_S: f64 = 1.0;

/// Wall seconds between two requests for a window's first plan (or the next window's)
/// when none came: an outage costs downtime, not the mission.
pub const PLAN_RETRY_S: f64 = 1.0;

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
const LEAST_T_EXEC_S: f64 = 1e-3;

/// The report's reason for a window given up before any plan came.
pub const NO_PLAN_REASON: &str = "no planner answered before the window was given up";

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

/// The missions of a window, numbered on from the previous windows'.
#[derive(Debug, Clone)]
struct MissionIds {
    robot: String,
    tag: String,
    window: usize,
    sent: u64,
}

impl MissionIds {
    fn next(&mut self, waypoints: Vec<[f64; 2]>, recovery: bool) -> Mission {
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
enum DriveAsk {
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
enum Follows {
    /// A replan, counted as `Replanned` says.
    Replan(Replanned),
    /// Straight to the task, curious no more.
    Straight,
}

/// The next window's request in flight.
#[derive(Debug, Clone, Copy, PartialEq)]
struct AheadAsk {
    budget_s: f64,
    time_left_s: f64,
    leave_at_s: f64,
}

/// The robot on its way.
#[derive(Debug, Clone)]
struct Drive {
    budget_s: f64,
    shortest: Vec<[f64; 2]>,
    /// Of the window's first route.
    planned_information: f64,
    late_probability: f64,
    /// Every route sent, in order.
    plans: Vec<Vec<[f64; 2]>>,
    /// The current route's waypoints.
    waypoints: Vec<[f64; 2]>,
    /// The current mission's id: statuses on any other are not about this route.
    mission: String,
    /// The current route is a curious one (the last-safe-moment rule watches it).
    route_curious: bool,
    first_sent_at_s: f64,
    sent_at_s: f64,
    /// The current route from where it was sent.
    path: Vec<[f64; 2]>,
    watch: Watch,
    reasons: Vec<String>,
    safe_checked_at_s: f64,
    /// The current mission is a recovery back to the last fix.
    recovering: bool,
    /// Since when the PEB guard holds the robot, if it does.
    held_since_s: Option<f64>,
    holds: u32,
    held_s: f64,
    recoveries: u32,
}

#[derive(Debug, Clone)]
enum Phase {
    /// Waiting for the window's first plan, asked again at `retry_at_wall_s` after a
    /// failure.
    FirstPlan {
        retry_at_wall_s: Option<f64>,
        failures: u32,
    },
    Driving(Box<Drive>),
    /// Arrived; at the task until `leave_at_s`.
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
    asks_made: u64,
    /// The next window's plan, once made.
    planned_ahead: Option<PlannedAhead>,
    began_s: f64,
    /// The robot's last good estimate.
    here: [f64; 2],
    /// The previous window's track end (`carried` points, for recoveries: see
    /// [`Handover::track`]), then where this window began and every good estimate
    /// until the robot arrived.
    driven: Vec<[f64; 2]>,
    carried: usize,
    /// The index in `driven` of the last estimate with a fix.
    last_fix: usize,
    /// The track handed to the next window, kept when the drive's outcome is made.
    track_out: Option<(Vec<[f64; 2]>, usize)>,
    pebs: Vec<f64>,
    drive_ask: Option<(u64, DriveAsk)>,
    ahead_ask: Option<(u64, AheadAsk)>,
    /// The window's requests, for its report (at most [`MAX_REPORTED_ASKS`]), and how
    /// many it made.
    asks: Vec<AskReport>,
    asks_in_window: u32,
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
        let mut driven = handover.track;
        let carried = driven.len();
        let last_fix = handover.fix.min(carried.saturating_sub(1));
        driven.push(from);
        let mut w = DowntimeWindow {
            ids: MissionIds {
                robot: setup.robot.clone(),
                tag: setup.mission_tag.clone(),
                window: setup.window,
                sent: handover.missions_sent,
            },
            asks_made: handover.asks_made,
            margin: handover.margin,
            planned_ahead: None,
            began_s: now.mission_s,
            here: from,
            driven,
            carried,
            last_fix,
            track_out: None,
            pebs: Vec::new(),
            drive_ask: None,
            ahead_ask: None,
            asks: Vec::new(),
            asks_in_window: 0,
            phase: Phase::FirstPlan {
                retry_at_wall_s: None,
                failures: 0,
            },
            setup,
        };
        let task = &w.setup.task;
        if now.mission_s >= task.start_s + task.duration_s {
            let done = w.finish(None);
            return (w, vec![WindowAction::Skipped, done]);
        }
        let window = w.setup.window;
        let ahead = handover.planned_ahead.filter(|p| {
            p.window == window
                && distance(p.from, from) <= PREPLAN_FROM_M
                && now.mission_s <= p.leave_at_s + PREPLAN_LATE_S
        });
        let actions = match ahead {
            Some(p) => w.start_driving(p.route, p.shortest, p.budget_s, p.time_left_s, now),
            None => w
                .set_off(now)
                .unwrap_or_else(|| vec![w.ask_first_plan(now)]),
        };
        (w, actions)
    }

    /// Sets off on the window's own fastest path and asks for the curious plan from
    /// where the robot will be when it comes (module doc, step 1); `None` when the rule
    /// is off, plans are not curious or there is no fastest path.
    fn set_off(&mut self, now: Now) -> Option<Vec<WindowAction>> {
        let rules = self.setup.rules;
        if !(rules.set_off_at_once && rules.curious) {
            return None;
        }
        let route = self.fastest_from_here()?;
        let time_left = self.setup.task.start_s - now.mission_s;
        let budget = self.margin.budget(time_left);
        let shortest = route.points.clone();
        let mut actions = self.start_driving(route, shortest, budget, time_left, now);
        let Phase::Driving(drive) = &self.phase else {
            return Some(actions);
        };
        // The window's own curious plan goes to the planner before the next window's
        // (asked as the robot set off): a planner answers one client's requests in
        // order, and a short first drive ends before a plan queued second comes.
        let ahead_at = actions
            .iter()
            .position(|a| matches!(a, WindowAction::RequestPlan(_)));
        let ahead: Vec<WindowAction> = match ahead_at {
            Some(i) => actions.split_off(i),
            None => Vec::new(),
        };
        let lead_m = self.plan_cost_s(time_left, now) * self.setup.watch.expected_speed_m_per_s;
        let from = straight::point_ahead(&drive.path, self.here, lead_m);
        let (to, start) = (self.setup.task.at, self.setup.task.start_s);
        let (ask, _, _) = self.ask(from, to, start, None, true, now);
        actions.extend(self.ask_replan(Reason::SetOff, true, ask));
        actions.extend(ahead);
        Some(actions)
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
            WindowEvent::PlanReply { id, plan } => self.on_reply(id, Some(*plan), now),
            WindowEvent::PlanFailed { id } => self.on_reply(id, None, now),
        }
    }

    /// The requests in flight (for the executive's status).
    pub fn asks_in_flight(&self) -> usize {
        usize::from(self.drive_ask.is_some()) + usize::from(self.ahead_ask.is_some())
    }

    fn start_driving(
        &mut self,
        route: Route,
        shortest: Vec<[f64; 2]>,
        budget_s: f64,
        time_left_s: f64,
        now: Now,
    ) -> Vec<WindowAction> {
        let waypoints = mission_waypoints(&route.points, self.setup.waypoint_spacing_m);
        let mission = self.ids.next(waypoints.clone(), false);
        let watch = Watch::new(
            self.setup.watch,
            self.setup.task.start_s,
            route.points.clone(),
            now.mission_s,
            now.wall_s,
        );
        let late_probability = self.margin.late_probability(route.t_eta_s, time_left_s);
        let planned = WindowAction::Planned {
            budget_s,
            eta_s: route.t_eta_s,
            curious: route.curious,
            late_probability,
        };
        self.phase = Phase::Driving(Box::new(Drive {
            budget_s,
            shortest,
            planned_information: self.setup.scale.of(&route.points),
            late_probability,
            path: std::iter::once(self.setup.from)
                .chain(route.points.iter().copied())
                .collect(),
            route_curious: route.curious,
            plans: vec![route.points],
            waypoints,
            mission: mission.id.clone(),
            first_sent_at_s: now.mission_s,
            sent_at_s: now.mission_s,
            watch,
            reasons: Vec::new(),
            safe_checked_at_s: f64::NEG_INFINITY,
            recovering: false,
            held_since_s: None,
            holds: 0,
            held_s: 0.0,
            recoveries: 0,
        }));
        let mut actions = vec![planned, WindowAction::Drive(mission)];
        actions.extend(self.ask_ahead_if_due(now));
        actions
    }

    /// The next window's plan, asked while this one drives (`plan_ahead`), unless it is
    /// in or asked.
    fn ask_ahead_if_due(&mut self, now: Now) -> Vec<WindowAction> {
        let due =
            self.setup.rules.plan_ahead && self.planned_ahead.is_none() && self.ahead_ask.is_none();
        if due {
            self.ask_next_window(now)
        } else {
            Vec::new()
        }
    }

    fn decide(&mut self, decision: Decision, now: Now) -> Vec<WindowAction> {
        match decision {
            Decision::Keep => Vec::new(),
            Decision::Arrived { at_s } => self.arrive(at_s, now),
            Decision::GiveUp => self.give_up(now),
            Decision::Replan {
                reason,
                curious,
                resend,
            } => self.replan(reason, curious, resend, now),
        }
    }

    /// The last-safe-moment rule (module doc).
    fn check_safe(&mut self, now: Now) -> Vec<WindowAction> {
        let Phase::Driving(drive) = &mut self.phase else {
            return Vec::new();
        };
        let watched = drive.route_curious && !drive.recovering && !drive.watch.slipped();
        if !watched || now.mission_s - drive.safe_checked_at_s < SAFE_CHECK_S {
            return Vec::new();
        }
        drive.safe_checked_at_s = now.mission_s;
        // The next check may come `SAFE_CHECK_S` later, and the curious route may take
        // the robot that long away from the task, which costs as long again to come
        // back: the rule fires when waiting for the next check would leave too little.
        let time_left = self.setup.task.start_s - now.mission_s - 2.0 * SAFE_CHECK_S;
        let budget = self.margin.budget(time_left);
        // What is left of the route is a way to the task, so the fastest path takes no
        // longer: while the budget covers the route left, no search is needed (on a
        // large map the search is the expensive part; this keeps it to the window's end).
        let (d, theta) = path_measure(&straight::route_left(&drive.path, self.here));
        if budget > self.setup.time_model.eta(d, theta) {
            return Vec::new();
        }
        let Some(fastest) = self.fastest_from_here() else {
            return Vec::new();
        };
        if budget > fastest.t_eta_s {
            return Vec::new();
        }
        self.go_straight(fastest, Reason::LastSafeMoment, now)
    }

    /// The window's own fastest path from where the robot is to the task.
    fn fastest_from_here(&self) -> Option<Route> {
        let s = &self.setup;
        straight::fastest_route(&s.scale, s.time_model, self.here, s.task.at)
    }

    /// Sends the robot along `route` (the window's own fastest path) at once, for
    /// `reason`; curious no more in this window.
    fn go_straight(&mut self, route: Route, reason: Reason, now: Now) -> Vec<WindowAction> {
        let mut actions = self.forget_drive_ask();
        let here = self.here;
        actions.extend(self.send_route(here, route, reason, Follows::Straight, now));
        actions
    }

    /// The robot now drives `route` from `from`, for `reason`: the watch follows it, the
    /// drive keeps it, and its mission is sent.
    fn send_route(
        &mut self,
        from: [f64; 2],
        route: Route,
        reason: Reason,
        follows: Follows,
        now: Now,
    ) -> Vec<WindowAction> {
        let spacing = self.setup.waypoint_spacing_m;
        let Phase::Driving(drive) = &mut self.phase else {
            return Vec::new();
        };
        let path: Vec<[f64; 2]> = std::iter::once(from)
            .chain(route.points.iter().copied())
            .collect();
        let (t, wall) = (now.mission_s, now.wall_s);
        match follows {
            Follows::Straight => drive.watch.straight(path.clone(), t, wall),
            Follows::Replan(kind) => drive.watch.replanned(path.clone(), kind, t, wall),
        }
        drive.reasons.push(reason.as_str().to_owned());
        drive.waypoints = mission_waypoints(&route.points, spacing);
        drive.route_curious = route.curious && follows != Follows::Straight;
        drive.plans.push(route.points);
        let mission = self.ids.next(drive.waypoints.clone(), false);
        drive.mission = mission.id.clone();
        drive.sent_at_s = t;
        drive.path = path;
        vec![
            WindowAction::Replanned { reason },
            WindowAction::Drive(mission),
        ]
    }

    /// The drive's request in flight is forgotten (its answer will be dropped).
    fn forget_drive_ask(&mut self) -> Vec<WindowAction> {
        self.drive_ask
            .take()
            .map(|(id, _)| WindowAction::Forget(id))
            .into_iter()
            .collect()
    }

    fn replan(
        &mut self,
        reason: Reason,
        curious: bool,
        resend: bool,
        now: Now,
    ) -> Vec<WindowAction> {
        // Late: straight to the task at once, on the window's own fastest path.
        if reason == Reason::EtaSlipped {
            if let Some(route) = self.fastest_from_here() {
                return self.go_straight(route, reason, now);
            }
        }
        let Phase::Driving(drive) = &self.phase else {
            return Vec::new();
        };
        // A slack or behind replan is made while the robot drives on: it starts where
        // the robot will be when the plan comes.
        let time_left = self.setup.task.start_s - now.mission_s;
        let from = match reason {
            Reason::Slack | Reason::Behind => {
                let lead_m =
                    self.plan_cost_s(time_left, now) * self.setup.watch.expected_speed_m_per_s;
                straight::point_ahead(&drive.path, self.here, lead_m)
            }
            _ => self.here,
        };
        let (to, start) = (self.setup.task.at, self.setup.task.start_s);
        let (ask, _, _) = self.ask(from, to, start, None, curious, now);
        self.ask_replan(reason, resend, ask)
    }
}

#[cfg(test)]
mod tests;
