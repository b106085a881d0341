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
//!    asked again [`PLAN_RETRY_S`] (wall) after a failure, the wait doubling with each
//!    failure in a row up to [`MAX_PLAN_RETRY_S`] (the next window's plan, asked while
//!    the robot is at its task, backs off the same way). After
//!    [`FALLBACK_AFTER_FAILURES`] failures the robot drives the fastest path the window
//!    computes itself (no planner: degrade, don't stop) and curiosity comes back
//!    through the slack rule. A restarted executive's first window drives on with the
//!    route its predecessor was driving, when it is this task's and still fits
//!    (`resume.rs`).
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
//! 4. **The last safe moment.** Once in each [`SAFE_CHECK_S`] of the mission clock on a
//!    curious route, the window computes the fastest path from where the robot's last
//!    estimate put it; when the budget the arrival margin leaves of the time left from
//!    that estimate's time, less twice the check's period, no
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
//! 6. **The map changed**: a new set of obstacles the fleet believes in
//!    ([`WindowEvent::MapChanged`]) that the route left passes too close to is a
//!    replan at once (`map_changed`), from where the robot will be when the plan comes
//!    and seeded with the route left, which the planner repairs round the block
//!    (`blocked.rs`).
//! 7. **Arrive**: the time model's prediction is scored, the arrival margin learns, the
//!    calibration gets the window's drives (`drove.rs`), and
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
mod blocked;
mod drove;
mod ending;
mod events;
mod handover;
mod heard;
mod holds;
mod replan;
mod replies;
mod resume;
mod resumed;
mod routes;
mod setup;
mod state;
mod straight;

use crate::path::{distance, mission_waypoints};
use crate::watch::{Reason, Watch};

use state::{Drive, MissionIds, Phase};

pub use crate::seen::{seen_world, SeenObstacles, MAX_OBSTACLE_POINTS};
pub use drove::{MAX_LEARNED_OFF_ROUTE_M, MIN_LEARNED_DRIVE_M};
pub use events::{DrivenMission, Now, PlanAsk, WindowAction, WindowEvent};
pub use handover::{Handover, WindowEnd, WindowOutcome};
pub use resume::RESUME_WITHIN_M;
pub use resumed::Resumed;
pub use routes::{routes, PlannedAhead, Route};
pub use setup::{
    plan_retry_after_s, WindowRules, WindowSetup, FALLBACK_AFTER_FAILURES, MAX_PLAN_RETRY_S,
    MAX_RECOVERIES, MIN_DEADLINE_S, NO_PLAN_REASON, PLAN_RETRY_S, PREPLAN_FROM_M, PREPLAN_LATE_S,
    RECOVERY_BACK_M, SAFE_CHECK_S,
};
pub use state::DowntimeWindow;

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
            here_at_s: now.mission_s,
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
            obstacles_unchecked: handover.obstacles.is_some(),
            seen_world: handover
                .obstacles
                .as_deref()
                .and_then(|o| crate::seen::seen_world(setup.scale.world, o)),
            obstacles: handover.obstacles,
            setup,
        };
        let task = &w.setup.task;
        if now.mission_s >= task.start_s + task.duration_s {
            let done = w.finish(None);
            return (w, vec![WindowAction::Skipped, done]);
        }
        if let Some(actions) = handover.resume.and_then(|r| w.resume(r, now)) {
            return (w, actions);
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
        let lead_m =
            self.plan_cost_s(time_left, now, false) * self.setup.watch.expected_speed_m_per_s;
        let from = straight::point_ahead(&drive.path, self.here, lead_m);
        let (to, start) = (self.setup.task.at, self.setup.task.start_s);
        let (ask, _, _) = self.ask(from, to, start, None, asks::Asking::Curious, now);
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
                time_s,
            } => self.on_estimate(position, peb_m, degraded, time_s, now),
            WindowEvent::Status(status) => self.on_status(&status, now),
            WindowEvent::Tick => self.on_tick(now),
            WindowEvent::PlanReply { id, plan } => self.on_reply(id, Some(*plan), now),
            WindowEvent::PlanFailed { id } => self.on_reply(id, None, now),
            WindowEvent::MapChanged(obstacles) => self.on_map_changed(obstacles, now),
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
            sent_here: (self.here, now.mission_s),
            drives: Vec::new(),
            watch,
            reasons: Vec::new(),
            safe_checked_at_s: f64::NEG_INFINITY,
            recovering: false,
            held_since_s: None,
            holds: 0,
            held_s: 0.0,
            sent_holds: 0,
            route_teaches: true,
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
}

#[cfg(test)]
mod tests;
