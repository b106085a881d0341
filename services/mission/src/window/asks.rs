//! The window's plan requests: their budgets and deadlines (the arrival margin after
//! the plan's expected cost, the deadline cut to what the time left affords), their ids,
//! and the record the window's report lists.

use roam_planner::plan::MAX_T_EXEC_S;
use roam_proto::mission::{AskReport, MAX_REPORTED_ASKS};

use super::events::{Now, PlanAsk, WindowAction};

/// What kind of plan a request asks for.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Asking {
    /// The shortest path (the planner's fastest path).
    Shortest,
    /// A curious plan from scratch, with the executive's `max_generations`.
    Curious,
    /// A curious replan seeded with the route the robot drives (from the request's
    /// start on), with `replan_generations`.
    Seeded(Vec<[f64; 2]>),
}
use super::setup::{LEAST_T_EXEC_S, MIN_DEADLINE_S};
use super::state::{AheadAsk, DowntimeWindow, DriveAsk};
use crate::watch::Reason;

impl DowntimeWindow<'_> {
    /// A request from `from` to `to` for a task starting at `task_start_s`, the robot
    /// leaving at `leave_at_s` at the earliest (now when `None`): its deadline cut to
    /// what the time left affords, its budget what the margin leaves after the plan's
    /// expected cost; with the time left that budget was made from.
    pub(super) fn ask(
        &mut self,
        from: [f64; 2],
        to: [f64; 2],
        task_start_s: f64,
        leave_at_s: Option<f64>,
        asking: Asking,
        now: Now,
    ) -> (PlanAsk, f64, f64) {
        let set_off = leave_at_s.map_or(now.mission_s, |at| at.max(now.mission_s));
        let time_left = (task_start_s - set_off).max(0.0);
        let deadline_s = self.deadline_s(time_left, now);
        let curious = asking != Asking::Shortest && self.setup.rules.curious;
        let seed_route = match asking {
            Asking::Seeded(route) if curious => route,
            _ => Vec::new(),
        };
        let cost = if curious {
            self.plan_cost_s(time_left, now, !seed_route.is_empty())
        } else {
            0.0
        };
        let earliest = now.mission_s + cost;
        let time_left = task_start_s - leave_at_s.map_or(earliest, |at| at.max(earliest));
        let budget_s = self.margin.budget(time_left);
        let ask = PlanAsk {
            id: self.next_ask_id(),
            from,
            to,
            t_exec_s: budget_s.clamp(LEAST_T_EXEC_S, MAX_T_EXEC_S),
            deadline_s,
            curious: curious && budget_s > 0.0,
            seed_route,
        };
        self.record(&ask, leave_at_s.is_some(), now);
        (ask, budget_s, time_left)
    }

    /// The deadline of a plan asked with `time_left_s` to its task, wall seconds: the
    /// configured one cut to `replan_time_share` of the time left at the clock's rate.
    pub(super) fn deadline_s(&self, time_left_s: f64, now: Now) -> f64 {
        let rules = self.setup.rules;
        rules
            .plan_deadline_s
            .min(rules.replan_time_share * time_left_s.max(0.0) / now.clock_rate.max(1e-9))
            .max(MIN_DEADLINE_S)
    }

    /// What a curious plan asked with `time_left_s` to its task costs on the mission
    /// clock: the expected cost (a seeded replan's when `seeded`), cut to what its
    /// deadline allows.
    pub(super) fn plan_cost_s(&self, time_left_s: f64, now: Now, seeded: bool) -> f64 {
        let cost = if seeded {
            now.replan_cost_s
        } else {
            now.planning_cost_s
        };
        cost.min(self.deadline_s(time_left_s, now) * now.clock_rate.max(1e-9))
    }

    /// The driving budget a curious replan asked now would get: what the arrival margin
    /// leaves of the time to the task after a curious plan's cost (the slack rule's
    /// measure). A slack replan is seeded and costs far less; the rule still charges a
    /// whole plan's cost, so that cheap replans do not fire on every few seconds the
    /// time model gains and spend the window's `max_replans` in its first half, leaving
    /// the robot early at the end (services/mission/README.md, "Seeded replans").
    pub(super) fn replan_budget_s(&self, now: Now) -> f64 {
        let time_left = self.setup.task.start_s - now.mission_s;
        self.margin
            .budget(time_left - self.plan_cost_s(time_left, now, false))
    }

    pub(super) fn next_ask_id(&mut self) -> u64 {
        self.asks_made += 1;
        self.asks_made
    }

    /// Keeps `ask` for the window's report.
    pub(super) fn record(&mut self, ask: &PlanAsk, ahead: bool, now: Now) {
        self.asks_in_window += 1;
        if self.asks.len() < MAX_REPORTED_ASKS {
            self.asks.push(AskReport {
                at_s: now.mission_s,
                from: ask.from,
                t_exec_s: ask.t_exec_s,
                curious: ask.curious,
                ahead,
            });
        }
    }

    pub(super) fn ask_first_plan(&mut self, now: Now) -> WindowAction {
        let (from, to, start) = (self.setup.from, self.setup.task.at, self.setup.task.start_s);
        let (ask, budget_s, time_left_s) = self.ask(from, to, start, None, Asking::Curious, now);
        self.drive_ask = Some((
            ask.id,
            DriveAsk::FirstPlan {
                budget_s,
                time_left_s,
            },
        ));
        WindowAction::RequestPlan(ask)
    }

    pub(super) fn ask_next_window(&mut self, now: Now) -> Vec<WindowAction> {
        let Some(next) = &self.setup.next else {
            return Vec::new();
        };
        let (start_s, to) = (next.start_s, next.at);
        let task = &self.setup.task;
        let (from, leave_at_s) = (task.at, task.start_s + task.duration_s);
        let (ask, budget_s, time_left_s) =
            self.ask(from, to, start_s, Some(leave_at_s), Asking::Curious, now);
        self.ahead_ask = Some((
            ask.id,
            AheadAsk {
                budget_s,
                time_left_s,
                leave_at_s,
            },
        ));
        vec![WindowAction::RequestPlan(ask)]
    }

    /// Asks `ask` as the drive's replan for `reason`.
    pub(super) fn ask_replan(
        &mut self,
        reason: Reason,
        resend: bool,
        ask: PlanAsk,
    ) -> Vec<WindowAction> {
        let request = WindowAction::RequestPlan(ask.clone());
        self.drive_ask = Some((
            ask.id,
            DriveAsk::Replan {
                reason,
                resend,
                ask,
            },
        ));
        vec![request]
    }
}
