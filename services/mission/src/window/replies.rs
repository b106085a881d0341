//! The planner's answers: a route for the drive (the first plan, a replan) or for the
//! next window, and what a failure leaves (the shortest path asked for, then the
//! window's own fastest path).

use roam_proto::planner::Plan;

use super::events::{Now, PlanAsk, WindowAction};
use super::routes::{routes, PlannedAhead, Route};
use super::setup::{plan_retry_after_s, FALLBACK_AFTER_FAILURES};
use super::state::{AheadAsk, DowntimeWindow, DriveAsk, Follows, Phase};
use crate::watch::{Reason, Replanned};

impl DowntimeWindow<'_> {
    pub(super) fn on_reply(&mut self, id: u64, plan: Option<Plan>, now: Now) -> Vec<WindowAction> {
        if self
            .drive_ask
            .as_ref()
            .is_some_and(|(asked, _)| *asked == id)
        {
            let Some((_, asked)) = self.drive_ask.take() else {
                return Vec::new();
            };
            return match plan.and_then(routes) {
                Some((route, shortest)) => self.on_drive_plan(asked, route, shortest, now),
                None => self.on_drive_failed(asked, now),
            };
        }
        if self.ahead_ask.is_some_and(|(asked, _)| asked == id) {
            let Some((_, asked)) = self.ahead_ask.take() else {
                return Vec::new();
            };
            return match plan.and_then(routes) {
                Some((route, shortest)) => self.on_ahead_plan(asked, route, shortest, now),
                None => self.on_ahead_failed(now),
            };
        }
        // A reply nobody waits for any more (forgotten, or an earlier window's).
        Vec::new()
    }

    pub(super) fn on_drive_plan(
        &mut self,
        asked: DriveAsk,
        route: Route,
        shortest: Vec<[f64; 2]>,
        now: Now,
    ) -> Vec<WindowAction> {
        match asked {
            DriveAsk::FirstPlan {
                budget_s,
                time_left_s,
            } => {
                if !matches!(self.phase, Phase::FirstPlan { .. }) {
                    return Vec::new();
                }
                self.start_driving(route, shortest, budget_s, time_left_s, now)
            }
            DriveAsk::Replan {
                reason,
                resend,
                ask,
            } => {
                if reason == Reason::SetOff {
                    self.took_set_off_plan(&route, ask.t_exec_s, now);
                }
                let kind = match (resend, ask.curious) {
                    (true, _) => Replanned::Resend,
                    (false, true) => Replanned::Curious,
                    (false, false) => Replanned::Shortest,
                };
                self.send_route(ask.from, route, reason, Follows::Replan(kind), now)
            }
        }
    }

    /// The curious plan asked as the robot set off is the window's plan: its budget,
    /// information and late probability are the report's.
    fn took_set_off_plan(&mut self, route: &Route, budget_s: f64, now: Now) {
        let time_left = self.setup.task.start_s - now.mission_s;
        let late_probability = self.margin.late_probability(route.t_eta_s, time_left);
        let information = self.setup.scale.of(&route.points);
        if let Phase::Driving(drive) = &mut self.phase {
            drive.budget_s = budget_s;
            drive.planned_information = information;
            drive.late_probability = late_probability;
        }
    }

    pub(super) fn on_drive_failed(&mut self, asked: DriveAsk, now: Now) -> Vec<WindowAction> {
        let task = &self.setup.task;
        match asked {
            DriveAsk::FirstPlan { .. } => {
                let Phase::FirstPlan { failures, .. } = self.phase else {
                    return Vec::new();
                };
                if now.mission_s > task.start_s + self.setup.give_up_after_s {
                    return self.give_up_without_a_plan();
                }
                let failures = failures + 1;
                if failures >= FALLBACK_AFTER_FAILURES {
                    if let Some(route) = self.fastest_from_here() {
                        return self.drive_without_a_planner(route, now);
                    }
                }
                self.phase = Phase::FirstPlan {
                    retry_at_wall_s: Some(now.wall_s + plan_retry_after_s(failures)),
                    failures,
                };
                Vec::new()
            }
            // The robot set off on the fastest path already: it drives on.
            DriveAsk::Replan {
                reason: Reason::SetOff,
                ..
            } => Vec::new(),
            // A curious plan that fails (busy, an outage) leaves the shortest way.
            DriveAsk::Replan {
                reason,
                resend,
                ask,
            } if ask.curious => {
                let ask = PlanAsk {
                    id: self.next_ask_id(),
                    curious: false,
                    seed_route: Vec::new(),
                    ..ask
                };
                self.record(&ask, false, now);
                self.ask_replan(reason, resend, ask)
            }
            // No planner at all: the window's own fastest path, or the path it had.
            DriveAsk::Replan { .. } => match self.fastest_from_here() {
                Some(route) => self.go_straight(route, Reason::NoPlanner, now),
                None => Vec::new(),
            },
        }
    }

    /// No planner answered the window's first plan: the robot drives the window's own
    /// fastest path (the report says so), and the slack rule may replan a curious one.
    pub(super) fn drive_without_a_planner(&mut self, route: Route, now: Now) -> Vec<WindowAction> {
        let time_left = self.setup.task.start_s - now.mission_s;
        let budget = self.margin.budget(time_left);
        let shortest = route.points.clone();
        let mut actions = self.start_driving(route, shortest, budget, time_left, now);
        if let Phase::Driving(drive) = &mut self.phase {
            drive.reasons.push(Reason::NoPlanner.name().to_owned());
        }
        actions.insert(
            0,
            WindowAction::Replanned {
                reason: Reason::NoPlanner,
            },
        );
        actions
    }

    pub(super) fn on_ahead_plan(
        &mut self,
        asked: AheadAsk,
        route: Route,
        shortest: Vec<[f64; 2]>,
        now: Now,
    ) -> Vec<WindowAction> {
        // A plan for a window that has begun would start from a place the robot may
        // have left: dropped.
        if now.mission_s <= asked.leave_at_s {
            self.planned_ahead = Some(PlannedAhead {
                window: self.setup.window + 1,
                from: self.setup.task.at,
                route,
                shortest,
                budget_s: asked.budget_s,
                time_left_s: asked.time_left_s,
                leave_at_s: asked.leave_at_s,
            });
        }
        self.finish_at_task_end(now)
    }

    pub(super) fn on_ahead_failed(&mut self, now: Now) -> Vec<WindowAction> {
        let Phase::AtTask {
            leave_at_s,
            retry_at_wall_s,
            failures,
            ..
        } = &mut self.phase
        else {
            // While driving: asked again at the arrival.
            return Vec::new();
        };
        let next_given_up = self
            .setup
            .next
            .as_ref()
            .is_none_or(|n| now.mission_s > n.start_s + self.setup.give_up_after_s);
        if now.mission_s < *leave_at_s && !next_given_up {
            *failures += 1;
            *retry_at_wall_s = Some(now.wall_s + plan_retry_after_s(*failures));
            return Vec::new();
        }
        self.finish_at_task_end(now)
    }
}
