//! What the window hears while the robot drives: its estimates (the track, the last
//! fix, off the path), the controller's status on the current mission (arrived, stuck,
//! held, recovering; any status is speech, so a held robot is never "silent"), and the
//! clock's ticks (give up, a silent controller, a retry that is due, the last safe
//! moment, a route not yet checked against the obstacles last heard).

use roam_proto::controller::{ControllerStatus, MissionState};

use super::drove;
use super::events::{Now, WindowAction};
use super::state::{DowntimeWindow, Phase};
use crate::watch::{Reason, Status};

impl DowntimeWindow<'_> {
    pub(super) fn on_estimate(
        &mut self,
        position: [f64; 2],
        peb_m: Option<f64>,
        degraded: bool,
        time_s: f64,
        now: Now,
    ) -> Vec<WindowAction> {
        // At the task (or done) the drive is over: nothing more is recorded.
        let driving = matches!(self.phase, Phase::FirstPlan { .. } | Phase::Driving(_));
        if degraded || !driving {
            return Vec::new();
        }
        self.here = position;
        // A time that is not a number (a peer's) is the time it was heard.
        self.here_at_s = if time_s.is_finite() {
            time_s
        } else {
            now.mission_s
        };
        if let Phase::Driving(drive) = &mut self.phase {
            drove::still_at_start(drive, position, self.here_at_s);
        }
        self.driven.push(position);
        self.pebs.extend(peb_m);
        if peb_m.is_some_and(|p| p <= self.setup.rules.fix_peb_m) {
            self.last_fix = self.driven.len() - 1;
        }
        let mut actions = match &mut self.phase {
            Phase::Driving(drive) if self.drive_ask.is_none() && !drive.recovering => {
                let decision = drive.watch.on_estimate(position);
                self.decide(decision, now)
            }
            _ => Vec::new(),
        };
        actions.extend(self.check_safe(now));
        actions
    }

    pub(super) fn on_status(&mut self, s: &ControllerStatus, now: Now) -> Vec<WindowAction> {
        let replan_budget_s = self.replan_budget_s(now);
        let Phase::Driving(drive) = &mut self.phase else {
            return Vec::new();
        };
        if s.mission.as_deref() != Some(drive.mission.as_str()) {
            return Vec::new();
        }
        drive.watch.heard(now.wall_s);
        let status = match s.state {
            MissionState::Completed => Status::Completed,
            MissionState::Stuck | MissionState::StepLimit => Status::Stuck,
            // The controller's acknowledgement of a new mission carries no distance yet:
            // heard, but no progress to measure (taking it as 0 m left would spoil the
            // robot's pace for the whole mission).
            MissionState::Active => match s.distance_left_m {
                Some(distance_left_m) => Status::Active { distance_left_m },
                None => Status::Other,
            },
            MissionState::HaltedPeb => Status::Halted,
            _ => Status::Other,
        };
        if status == Status::Halted {
            return self.on_held(now);
        }
        if let Some(since) = drive.held_since_s.take() {
            drive.held_s += now.mission_s - since;
        }
        if drive.recovering {
            return match status {
                // Back at the fix (or stuck on the way): straight to the task from
                // there. A curious route would lead back into the coverage gap it was
                // held in (the planner does not know where the guard holds robots).
                Status::Completed | Status::Stuck => {
                    drive.recovering = false;
                    match self.fastest_from_here() {
                        Some(route) => self.go_straight(route, Reason::Recovered, now),
                        None => self.replan(Reason::Recovered, false, true, now),
                    }
                }
                _ => Vec::new(),
            };
        }
        if status == Status::Completed {
            // Arrived: a replan in flight is no longer wanted.
            let mut actions = self.forget_drive_ask();
            actions.extend(self.arrive(now.mission_s, now));
            return actions;
        }
        if self.drive_ask.is_some() {
            return self.check_safe(now);
        }
        let decision = drive
            .watch
            .on_status(status, now.mission_s, now.wall_s, replan_budget_s);
        let mut actions = self.decide(decision, now);
        actions.extend(self.check_safe(now));
        actions
    }

    pub(super) fn on_tick(&mut self, now: Now) -> Vec<WindowAction> {
        let due = |retry: &mut Option<f64>| {
            let due = retry.is_some_and(|at| now.wall_s >= at);
            if due {
                *retry = None;
            }
            due
        };
        match &mut self.phase {
            Phase::FirstPlan {
                retry_at_wall_s, ..
            } => {
                if self.drive_ask.is_none() && due(retry_at_wall_s) {
                    vec![self.ask_first_plan(now)]
                } else {
                    Vec::new()
                }
            }
            Phase::Driving(drive) => {
                let give_up = now.mission_s > self.setup.task.start_s + self.setup.give_up_after_s;
                if self.drive_ask.is_some() || drive.recovering {
                    return if give_up {
                        self.give_up(now)
                    } else {
                        self.check_safe(now)
                    };
                }
                let decision = drive.watch.on_tick(now.mission_s, now.wall_s);
                let mut actions = self.decide(decision, now);
                actions.extend(self.check_safe(now));
                // A set of obstacles heard while a plan was in flight (`blocked.rs`).
                actions.extend(self.check_route_clear(now));
                actions
            }
            Phase::AtTask {
                leave_at_s,
                retry_at_wall_s,
                ..
            } => {
                let leave_at_s = *leave_at_s;
                if self.ahead_ask.is_none() && now.mission_s < leave_at_s && due(retry_at_wall_s) {
                    self.ask_next_window(now)
                } else {
                    self.finish_at_task_end(now)
                }
            }
            Phase::Done => Vec::new(),
        }
    }
}
