//! The executive's replan policy for one downtime window, as a plain state machine: what
//! the robot's estimates, the controller's statuses and the passing of time mean for the
//! plan. No Zenoh, no clock of its own: the executive feeds it events with the mission
//! time and does what it decides, and the tests feed it events directly.
//!
//! The rules, in the order they are checked:
//! - **arrived**: the controller reports the mission completed;
//! - **given up**: `give_up_after_s` past the task's start without arriving;
//! - **lost mission**: no status on the current mission for `controller_silence_s` (wall
//!   time): the mission is sent again (a fresh plan from where the robot is), however
//!   many replans the window already had;
//! - **blocked**: the controller reports the robot stuck: replan the shortest way (once
//!   its budget is spent, try the way again, uncounted, once per `slack_interval_s`);
//! - **late**: the ETA (distance left at the robot's speed) slips past the task's start:
//!   replan the shortest way, once, and never curious again in this window;
//! - **behind**: at the robot's own progress along the path (once it has driven a few
//!   seconds) it would arrive after the task's start, though at its top speed it would
//!   not: the time model underestimated this path (a slow stretch, turns the model
//!   does not charge). Replan a curious path from where it is with the time left (the
//!   executive's arrival margin included), at most once per `slack_interval_s`: cheaper
//!   than giving the rest of the window to the shortest path, and if the robot still
//!   falls behind, the late rule takes over;
//! - **pushed off the path**: an estimate farther than `off_path_m` from the path;
//! - **slack**: a plan asked now would get a driving budget (what the arrival margin
//!   leaves of the time left after the plan's cost, reckoned by the window,
//!   [`crate::window`]) more than `slack_s` longer than the drive the robot still has
//!   (predicted from its own progress along the path once it has driven a few seconds,
//!   from the time model before): the time model overestimated the drive, or the margin
//!   the plan kept back is no longer needed this close to the task. Replan a curious
//!   path with the time left, the mirror of the late rule. At most once per
//!   `slack_interval_s`, and never after the window slipped. The robot drives on while
//!   the plan is made; the window plans from where it will be when the plan comes.
//!   Comparing budgets, not arrival times, keeps the rule from firing on the margin
//!   itself: a robot arriving early by exactly what a new plan would keep back has no
//!   slack.
//!
//! - **map changed**: the window found the route left passing what the fleet has
//!   seen (`window/blocked.rs`): replan round it, curious while the route is.
//!
//! Slack and behind replans need `min_replan_window_s` left to the task: a short
//! replan near a window's end is the one a time model gets most wrong.
//!
//! Curious replans (slack, behind, pushed off before slipping) count toward
//! `max_replans`; the shortest-way ones (blocked, late, pushed off after slipping) toward
//! a budget of their own of the same size; resending a lost mission toward neither. So a
//! window that spent its curious replans on slack can still get a stuck robot moving
//! (the controller holds a stuck robot until it is given a new mission).

use crate::path::{eta_slips, off_path_m};

/// Which budget a new plan came out of ([`Watch::replanned`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Replanned {
    /// A curious replan: `max_replans`.
    Curious,
    /// A shortest-way replan: a budget of its own of the same size.
    Shortest,
    /// A lost mission sent again, or a recovery: not counted.
    Resend,
}

/// The policy's parameters (the executive's config, in the units it uses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WatchParams {
    pub off_path_m: f64,
    /// The speed the late rule assumes (the slower of the configured speed and the time
    /// model's), m/s.
    pub speed_m_per_s: f64,
    /// The speed the slack rule expects (the time model's, 1 / v_lin), m/s.
    pub expected_speed_m_per_s: f64,
    pub max_replans: u32,
    pub give_up_after_s: f64,
    pub controller_silence_s: f64,
    /// A replan's budget this much longer than the drive left is slack to spend, seconds.
    pub slack_s: f64,
    /// Mission seconds between two slack replans at least (and two behind ones).
    pub slack_interval_s: f64,
    /// Slack and behind replans only with at least this much time left to the task.
    pub min_replan_window_s: f64,
    /// The behind rule is on.
    pub behind: bool,
}

/// Why the window's plan changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    ControllerSilent,
    Stuck,
    EtaSlipped,
    PushedOffPath,
    Slack,
    Behind,
    /// The time left, less the margin, reached the fastest path's time: straight there.
    LastSafeMoment,
    /// The robot was held for its PEB and driven back to where it had a fix.
    Recovered,
    /// No planner answered: the fastest path the executive computes itself.
    NoPlanner,
    /// The window's curious plan, made while the robot set off on the fastest path.
    SetOff,
    /// What the fleet has seen blocks the route ahead (`window/blocked.rs`).
    MapChanged,
    /// A restarted executive drives on with its predecessor's route (`window/resume.rs`).
    Resumed,
}

impl Reason {
    /// Every reason, in the order [`Reason::name`] lists them.
    pub const ALL: [Reason; 12] = [
        Reason::ControllerSilent,
        Reason::Stuck,
        Reason::EtaSlipped,
        Reason::PushedOffPath,
        Reason::Slack,
        Reason::Behind,
        Reason::LastSafeMoment,
        Reason::Recovered,
        Reason::NoPlanner,
        Reason::SetOff,
        Reason::MapChanged,
        Reason::Resumed,
    ];

    /// The reason's token: what the window's report carries on the wire
    /// (`WindowReport::replan_reasons`), stable, for a program to branch on, and what
    /// tables name it.
    pub fn name(self) -> &'static str {
        match self {
            Reason::ControllerSilent => "silent",
            Reason::Stuck => "stuck",
            Reason::EtaSlipped => "late",
            Reason::PushedOffPath => "off_path",
            Reason::Slack => "slack",
            Reason::Behind => "behind",
            Reason::LastSafeMoment => "last_safe_moment",
            Reason::Recovered => "recovered",
            Reason::NoPlanner => "no_planner",
            Reason::SetOff => "set_off",
            Reason::MapChanged => "map_changed",
            Reason::Resumed => "resumed",
        }
    }

    /// The reason whose token ([`Reason::name`]) is `name`.
    pub fn of_name(name: &str) -> Option<Reason> {
        Reason::ALL.into_iter().find(|r| r.name() == name)
    }

    /// The reason said to a person (the demo's progress, logs).
    pub fn sentence(self) -> &'static str {
        match self {
            Reason::ControllerSilent => "the controller went silent on the mission",
            Reason::Stuck => "stuck: the path is blocked",
            Reason::EtaSlipped => "the ETA slipped past the task's start",
            Reason::PushedOffPath => "pushed off the path",
            Reason::Slack => "slack: arriving early, a curious path with the time left",
            Reason::Behind => "behind the plan: a curious path with the time left",
            Reason::LastSafeMoment => "the last safe moment: the fastest path now, or late",
            Reason::Recovered => "recovered from a PEB hold: a new path from where it has a fix",
            Reason::NoPlanner => "no planner answered: the fastest path the executive computes",
            Reason::SetOff => "the curious path, planned while the robot set off on the fastest",
            Reason::MapChanged => "the map changed: what the fleet has seen blocks the route ahead",
            Reason::Resumed => "restarted: driving on with the predecessor's route",
        }
    }
}

/// What the executive should do after an event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Decision {
    /// Nothing changes.
    Keep,
    /// Plan again from where the robot is; `curious` asks for a curious path when it
    /// fits, the shortest otherwise; `resend` marks a lost mission (not counted).
    Replan {
        reason: Reason,
        curious: bool,
        resend: bool,
    },
    /// The robot reached the task's place at this mission time.
    Arrived { at_s: f64 },
    /// The window is given up.
    GiveUp,
}

/// What the controller said about the current mission.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Status {
    Active {
        distance_left_m: f64,
    },
    Completed,
    Stuck,
    /// Held by the PEB guard (the window acts on it, [`crate::window`]).
    Halted,
    Other,
}

/// One window's watch.
#[derive(Debug, Clone)]
pub struct Watch {
    params: WatchParams,
    task_start_s: f64,
    /// The path the robot should be on (world metres).
    path: Vec<[f64; 2]>,
    slipped: bool,
    replans: u32,
    shortest_replans: u32,
    resends: u32,
    /// Wall seconds (executive's clock) when the controller was last heard on the
    /// current mission.
    heard_at_wall_s: f64,
    /// Mission time of the last plan (first or replan).
    planned_at_s: f64,
    /// The first status on the current mission: when, and how far the robot had to go.
    progress_from: Option<(f64, f64)>,
}

/// Mission seconds of driving after which the robot's own progress, rather than the time
/// model, predicts its arrival for the slack rule.
const PROGRESS_AFTER_S: f64 = 3.0;

impl Watch {
    /// The watch of a window whose first plan was made at mission time `now_s` (wall
    /// time `wall_s`) for a task starting at `task_start_s`.
    pub fn new(
        params: WatchParams,
        task_start_s: f64,
        path: Vec<[f64; 2]>,
        now_s: f64,
        wall_s: f64,
    ) -> Watch {
        Watch {
            params,
            task_start_s,
            path,
            slipped: false,
            replans: 0,
            shortest_replans: 0,
            resends: 0,
            heard_at_wall_s: wall_s,
            planned_at_s: now_s,
            progress_from: None,
        }
    }

    /// Curious replans so far.
    pub fn replans(&self) -> u32 {
        self.replans
    }

    /// Shortest-way replans so far.
    pub fn shortest_replans(&self) -> u32 {
        self.shortest_replans
    }

    /// Lost missions resent so far.
    pub fn resends(&self) -> u32 {
        self.resends
    }

    /// The controller spoke on the current mission at wall time `wall_s`, whatever it
    /// said: held for the PEB or driving a recovery, it is not silent, and a
    /// "controller silent" replan would only resend a mission it is answering.
    pub fn heard(&mut self, wall_s: f64) {
        self.heard_at_wall_s = wall_s;
    }

    /// The time passes: give up, or resend a lost mission.
    pub fn on_tick(&mut self, now_s: f64, wall_s: f64) -> Decision {
        if now_s > self.task_start_s + self.params.give_up_after_s {
            return Decision::GiveUp;
        }
        if wall_s - self.heard_at_wall_s >= self.params.controller_silence_s {
            self.heard_at_wall_s = wall_s;
            return Decision::Replan {
                reason: Reason::ControllerSilent,
                curious: !self.slipped,
                resend: true,
            };
        }
        Decision::Keep
    }

    /// An estimate of the robot (not degraded).
    pub fn on_estimate(&mut self, position: [f64; 2]) -> Decision {
        if off_path_m(position, &self.path) > self.params.off_path_m {
            return self.replan(Reason::PushedOffPath, !self.slipped);
        }
        Decision::Keep
    }

    /// A status of the controller on the current mission; a plan asked now would get a
    /// driving budget of `replan_budget_s` (the window's reckoning: the margin and the
    /// plan's cost taken off the time left).
    pub fn on_status(
        &mut self,
        status: Status,
        now_s: f64,
        wall_s: f64,
        replan_budget_s: f64,
    ) -> Decision {
        self.heard_at_wall_s = wall_s;
        match status {
            Status::Completed => Decision::Arrived { at_s: now_s },
            Status::Stuck => {
                let decision = self.replan(Reason::Stuck, false);
                if decision == Decision::Keep
                    && now_s - self.planned_at_s >= self.params.slack_interval_s
                {
                    // Out of budget, a stuck robot is held until a new mission, and what
                    // blocks one in a fleet moves (a tug, a cart, a person): the way is
                    // tried again from where it is, uncounted, at most once per
                    // `slack_interval_s`, until the window gives up.
                    return Decision::Replan {
                        reason: Reason::Stuck,
                        curious: false,
                        resend: true,
                    };
                }
                decision
            }
            Status::Active { distance_left_m } if !self.slipped => {
                let (t0, d0) = *self.progress_from.get_or_insert((now_s, distance_left_m));
                let progress_speed = (d0 - distance_left_m) / (now_s - t0);
                // The robot's own progress along the path, once it has driven a few
                // seconds: it counts the turns and slow stretches that the distance
                // at top speed leaves out.
                let progress = (now_s - t0 >= PROGRESS_AFTER_S && progress_speed > 0.0)
                    .then_some(progress_speed);
                if eta_slips(
                    now_s,
                    distance_left_m,
                    self.params.speed_m_per_s,
                    self.task_start_s,
                ) {
                    self.slipped = true;
                    return self.replan(Reason::EtaSlipped, false);
                }
                // A replan near the window's end is the one a time model gets most
                // wrong: none with less than `min_replan_window_s` left.
                let spaced = now_s - self.planned_at_s >= self.params.slack_interval_s
                    && self.task_start_s - now_s >= self.params.min_replan_window_s;
                if let (Some(pace), true) = (progress, self.params.behind) {
                    if spaced && eta_slips(now_s, distance_left_m, pace, self.task_start_s) {
                        return self.replan(Reason::Behind, true);
                    }
                }
                let speed = progress.unwrap_or(self.params.expected_speed_m_per_s);
                let drive_left_s = distance_left_m / speed;
                if replan_budget_s - drive_left_s > self.params.slack_s && spaced {
                    return self.replan(Reason::Slack, true);
                }
                Decision::Keep
            }
            Status::Active { .. } | Status::Halted | Status::Other => Decision::Keep,
        }
    }

    /// The executive made a new plan at mission time `now_s` (wall `wall_s`): the robot
    /// should now be on `path`.
    pub fn replanned(&mut self, path: Vec<[f64; 2]>, kind: Replanned, now_s: f64, wall_s: f64) {
        self.path = path;
        self.planned_at_s = now_s;
        self.progress_from = None;
        self.heard_at_wall_s = wall_s;
        match kind {
            Replanned::Curious => self.replans += 1,
            Replanned::Shortest => self.shortest_replans += 1,
            Replanned::Resend => self.resends += 1,
        }
    }

    /// The window sent the robot straight to the task (the last safe moment): never
    /// curious again, as after the ETA slipped.
    pub fn straight(&mut self, path: Vec<[f64; 2]>, now_s: f64, wall_s: f64) {
        self.slipped = true;
        self.replanned(path, Replanned::Resend, now_s, wall_s);
    }

    /// Whether the robot was sent the shortest way for good (the ETA slipped, or the
    /// last safe moment came).
    pub fn slipped(&self) -> bool {
        self.slipped
    }

    /// What the fleet has seen blocks the route ahead: replan round it, curious while
    /// the route is (from `max_replans`), else the shortest way (from its own budget).
    pub fn on_route_blocked(&self, curious: bool) -> Decision {
        self.replan(Reason::MapChanged, curious && !self.slipped)
    }

    fn replan(&self, reason: Reason, curious: bool) -> Decision {
        let used = if curious {
            self.replans
        } else {
            self.shortest_replans
        };
        if used >= self.params.max_replans {
            return Decision::Keep;
        }
        Decision::Replan {
            reason,
            curious,
            resend: false,
        }
    }
}

#[cfg(test)]
mod tests;
