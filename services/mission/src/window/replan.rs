//! The robot's route changed while it drives: the watch's decisions, replans, the last
//! safe moment and going straight to the task.

use crate::calibration::path_measure;
use crate::path::mission_waypoints;
use crate::watch::{Decision, Reason};

use super::asks::Asking;
use super::drove;
use super::events::{Now, WindowAction};
use super::routes::Route;
use super::setup::SAFE_CHECK_S;
use super::state::{DowntimeWindow, Follows, Phase};
use super::straight;

impl DowntimeWindow<'_> {
    pub(super) fn decide(&mut self, decision: Decision, now: Now) -> Vec<WindowAction> {
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
    pub(super) fn check_safe(&mut self, now: Now) -> Vec<WindowAction> {
        let Phase::Driving(drive) = &mut self.phase else {
            return Vec::new();
        };
        // The check is of where the robot was seen and when: its last estimate, while
        // that is fresher than a check's period (else the clock's time, so a robot not
        // heard from is checked all the same). And it runs once in each period of
        // SAFE_CHECK_S on the mission clock, counted from 0, not from the last check:
        // a check's time never drifts with the events that happened to run it, so the
        // live executive (whose ticks come before a step's estimate, between steps)
        // and the batch check the same estimates.
        let seen_s = if now.mission_s - self.here_at_s < SAFE_CHECK_S {
            self.here_at_s
        } else {
            now.mission_s
        };
        let watched = drive.route_curious && !drive.recovering && !drive.watch.slipped();
        let period = |t: f64| (t / SAFE_CHECK_S).floor();
        if !watched || period(seen_s) <= period(drive.safe_checked_at_s) {
            return Vec::new();
        }
        drive.safe_checked_at_s = seen_s;
        // The next check may come up to `SAFE_CHECK_S` later (more, by a step), and the
        // curious route may take the robot that long away from the task, which costs as
        // long again to come back: the rule fires when waiting for the next check would
        // leave too little.
        let time_left = self.setup.task.start_s - seen_s - 2.0 * SAFE_CHECK_S;
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

    /// The window's own fastest path from where the robot is to the task: round the
    /// obstacles the fleet believes in (`blocked.rs`) when there is such a way, else on
    /// the static map (a robot standing within an obstacle's clearance has no free
    /// start on the blocked world).
    pub(super) fn fastest_from_here(&self) -> Option<Route> {
        let s = &self.setup;
        let on = |world| {
            let scale = crate::information::InformationScale {
                world,
                params: s.scale.params,
            };
            straight::fastest_route(&scale, s.time_model, self.here, s.task.at)
        };
        self.seen_world
            .as_ref()
            .and_then(&on)
            .or_else(|| on(s.scale.world))
    }

    /// Sends the robot along `route` (the window's own fastest path) at once, for
    /// `reason`; curious no more in this window.
    pub(super) fn go_straight(
        &mut self,
        route: Route,
        reason: Reason,
        now: Now,
    ) -> Vec<WindowAction> {
        let mut actions = self.forget_drive_ask();
        let here = self.here;
        actions.extend(self.send_route(here, route, reason, Follows::Straight, now));
        actions
    }

    /// The robot now drives `route` from `from`, for `reason`: the watch follows it, the
    /// drive keeps it, and its mission is sent.
    pub(super) fn send_route(
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
        let normally_driven = drive.route_teaches
            && drove::teaches(reason)
            && !drive.recovering
            && drive.held_since_s.is_none()
            && drive.holds == drive.sent_holds;
        let drove = normally_driven
            .then(|| drove::driven_part(&drive.path, drive.sent_here, (self.here, self.here_at_s)))
            .flatten();
        match follows {
            Follows::Straight => drive.watch.straight(path.clone(), t, wall),
            Follows::Replan(kind) => drive.watch.replanned(path.clone(), kind, t, wall),
        }
        drive.reasons.push(reason.name().to_owned());
        drive.waypoints = mission_waypoints(&route.points, spacing);
        drive.route_curious = route.curious && follows != Follows::Straight;
        drive.plans.push(route.points);
        let mission = self.ids.next(drive.waypoints.clone(), false);
        drive.mission = mission.id.clone();
        drive.sent_at_s = t;
        drive.sent_holds = drive.holds;
        drive.route_teaches = drove::route_teaches(reason);
        drive.sent_here = (self.here, self.here_at_s);
        drive.path = path;
        if drive.drives.len() < drove::MAX_LEARNED_DRIVES {
            drive.drives.extend(drove);
        }
        vec![
            WindowAction::Replanned { reason },
            WindowAction::Drive(mission),
        ]
    }

    /// The drive's request in flight is forgotten (its answer will be dropped).
    pub(super) fn forget_drive_ask(&mut self) -> Vec<WindowAction> {
        self.drive_ask
            .take()
            .map(|(id, _)| WindowAction::Forget(id))
            .into_iter()
            .collect()
    }

    pub(super) fn replan(
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
        // A slack, behind or map-changed replan is made while the robot drives on: it starts where
        // the robot will be when the plan comes, on its route, and is seeded with what
        // is left of the route from there (and runs the replan's generations, so it
        // comes sooner). One made where the robot is (off its path, stuck) is not: the
        // route left does not start there, the seed could not be joined, and fewer
        // generations from scratch would leave twisty random-walk paths.
        let time_left = self.setup.task.start_s - now.mission_s;
        let on_route = matches!(reason, Reason::Slack | Reason::Behind | Reason::MapChanged);
        let from = if on_route {
            let lead_m =
                self.plan_cost_s(time_left, now, curious) * self.setup.watch.expected_speed_m_per_s;
            straight::point_ahead(&drive.path, self.here, lead_m)
        } else {
            self.here
        };
        let asking = match (curious, on_route) {
            (false, _) => Asking::Shortest,
            (true, true) => Asking::Seeded(straight::route_left(&drive.path, from)),
            (true, false) => Asking::Curious,
        };
        let (to, start) = (self.setup.task.at, self.setup.task.start_s);
        let (ask, _, _) = self.ask(from, to, start, None, asking, now);
        self.ask_replan(reason, resend, ask)
    }
}
