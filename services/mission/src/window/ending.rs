//! How a window ends: the arrival (the time model's prediction scored, the arrival
//! margin taught, the next window asked for while the robot is at the task), giving up
//! (with or without a plan), and the outcome: the window's report with the paths
//! planned, driven and the shortest.

use roam_proto::mission::{TimeModelReport, WindowReport, MAX_REPORTED_ASKS};

use super::drove::{driven_part, from_where_sent};
use super::events::{Now, WindowAction};
use super::handover::{Handover, WindowEnd, WindowOutcome};
use super::setup::NO_PLAN_REASON;
use super::state::{DowntimeWindow, Drive, Phase};
use crate::calibration::path_measure;

impl DowntimeWindow<'_> {
    pub(super) fn arrive(&mut self, at_s: f64, now: Now) -> Vec<WindowAction> {
        let Phase::Driving(drive) = std::mem::replace(&mut self.phase, Phase::Done) else {
            return Vec::new();
        };
        let mut drive = drive;
        let held = drive.held_since_s.is_some() || drive.holds != drive.sent_holds;
        if let Some(since) = drive.held_since_s.take() {
            drive.held_s += at_s - since;
        }
        let model = self.setup.time_model;
        // The margin learns the window's own arrival: from the route's sending to the
        // arrival heard, over the route from where the robot was when it was sent.
        let took_s = at_s - drive.sent_at_s;
        let (d, theta) = path_measure(from_where_sent(&drive.path, drive.sent_here.0));
        let predicted_s = model.eta(d, theta);
        self.margin.learn(predicted_s, took_s);
        let time_model = TimeModelReport {
            v_lin: model.v_lin,
            v_ang: model.v_ang,
            predicted_s,
            driving_s: took_s,
            driven_share: self.share_driven(at_s - drive.first_sent_at_s),
        };
        // The calibration learns the robot's driving: as a replaced route's, timed by
        // the estimates (the arrival is heard later, by a lag that is not driving).
        let mut drives = std::mem::take(&mut drive.drives);
        if drive.route_teaches && !held {
            drives.extend(driven_part(
                &drive.path,
                drive.sent_here,
                (self.here, self.here_at_s),
            ));
        }
        let arrived = WindowAction::Arrived { at_s, drives };
        let outcome = self.outcome(*drive, Some(at_s), time_model);
        let task = &self.setup.task;
        let leave_at_s = task.start_s + task.duration_s;
        self.phase = Phase::AtTask {
            outcome: Box::new(outcome),
            leave_at_s,
            retry_at_wall_s: None,
            failures: 0,
        };
        let mut actions = vec![arrived];
        let ask_now = self.setup.next.is_some()
            && self.planned_ahead.is_none()
            && self.ahead_ask.is_none()
            && now.mission_s < leave_at_s;
        if ask_now {
            actions.extend(self.ask_next_window(now));
        } else {
            actions.extend(self.finish_at_task_end(now));
        }
        actions
    }

    pub(super) fn give_up(&mut self, now: Now) -> Vec<WindowAction> {
        let Phase::Driving(mut drive) = std::mem::replace(&mut self.phase, Phase::Done) else {
            return Vec::new();
        };
        if let Some(since) = drive.held_since_s.take() {
            drive.held_s += now.mission_s - since;
        }
        let model = self.setup.time_model;
        let time_model = TimeModelReport {
            v_lin: model.v_lin,
            v_ang: model.v_ang,
            predicted_s: 0.0,
            driving_s: 0.0,
            driven_share: 0.0,
        };
        let outcome = self.outcome(*drive, None, time_model);
        vec![WindowAction::GaveUp, self.finish(Some(outcome))]
    }

    /// Given up before any plan came: reported like any window given up, with nothing
    /// planned or driven.
    pub(super) fn give_up_without_a_plan(&mut self) -> Vec<WindowAction> {
        let task = &self.setup.task;
        let report = WindowReport {
            robot: self.setup.robot.clone(),
            task: task.name.clone(),
            window: self.setup.window,
            began_s: self.began_s,
            task_start_s: task.start_s,
            arrival_s: None,
            on_time: false,
            budget_s: task.start_s - self.began_s,
            planned_information: 0.0,
            driven_information: 0.0,
            shortest_information: 0.0,
            peb_mean_m: None,
            replans: 0,
            replan_reasons: vec![NO_PLAN_REASON.into()],
            time_model: None,
            late_probability: None,
            holds: 0,
            held_s: 0.0,
            recoveries: 0,
            asks: std::mem::take(&mut self.asks),
            asks_made: self.asks_in_window,
        };
        let outcome = WindowOutcome {
            report,
            plans: Vec::new(),
            shortest: Vec::new(),
            driven: vec![self.setup.from],
        };
        vec![WindowAction::GaveUp, self.finish(Some(outcome))]
    }

    /// The share of the window's time (its begin to the task's start) that `driving_s`
    /// is.
    pub(super) fn share_driven(&self, driving_s: f64) -> f64 {
        let window_s = self.setup.task.start_s - self.began_s;
        if window_s > 0.0 {
            driving_s / window_s
        } else {
            0.0
        }
    }

    pub(super) fn outcome(
        &mut self,
        drive: Drive,
        arrival_s: Option<f64>,
        time_model: TimeModelReport,
    ) -> WindowOutcome {
        let task = &self.setup.task;
        self.track_out = Some(super::handover::carried(&self.driven, self.last_fix));
        let mut driven = std::mem::take(&mut self.driven);
        // The previous window's track, carried for recoveries, is not this window's.
        let driven = driven.split_off(self.carried.min(driven.len()));
        let pebs = &self.pebs;
        let report = WindowReport {
            robot: self.setup.robot.clone(),
            task: task.name.clone(),
            window: self.setup.window,
            began_s: self.began_s,
            task_start_s: task.start_s,
            arrival_s,
            on_time: arrival_s.is_some_and(|a| a <= task.start_s),
            budget_s: drive.budget_s,
            planned_information: drive.planned_information,
            driven_information: self.setup.scale.of(&driven),
            shortest_information: self.setup.scale.of(&drive.shortest),
            peb_mean_m: (!pebs.is_empty()).then(|| pebs.iter().sum::<f64>() / pebs.len() as f64),
            replans: drive.reasons.len() as u32,
            replan_reasons: drive.reasons,
            time_model: Some(time_model),
            late_probability: Some(drive.late_probability),
            holds: drive.holds,
            held_s: drive.held_s,
            recoveries: drive.recoveries,
            asks: std::mem::take(&mut self.asks),
            asks_made: self.asks_in_window,
        };
        WindowOutcome {
            report,
            plans: drive.plans,
            shortest: drive.shortest,
            driven,
        }
    }

    /// At the task: done once it ends and no request is in flight.
    pub(super) fn finish_at_task_end(&mut self, now: Now) -> Vec<WindowAction> {
        let Phase::AtTask { leave_at_s, .. } = self.phase else {
            return Vec::new();
        };
        if self.ahead_ask.is_some() || now.mission_s < leave_at_s {
            return Vec::new();
        }
        let Phase::AtTask { mut outcome, .. } = std::mem::replace(&mut self.phase, Phase::Done)
        else {
            return Vec::new();
        };
        // The requests made at the task (the next window's) belong to this window too.
        let report = &mut outcome.report;
        let room = MAX_REPORTED_ASKS.saturating_sub(report.asks.len());
        report.asks.extend(self.asks.drain(..).take(room));
        report.asks_made = self.asks_in_window;
        vec![self.finish(Some(*outcome))]
    }

    pub(super) fn finish(&mut self, outcome: Option<WindowOutcome>) -> WindowAction {
        self.phase = Phase::Done;
        self.drive_ask = None;
        self.ahead_ask = None;
        let (track, fix) = self
            .track_out
            .take()
            .unwrap_or_else(|| super::handover::carried(&self.driven, self.last_fix));
        WindowAction::Done(Box::new(WindowEnd {
            outcome,
            handover: Handover {
                margin: self.margin.clone(),
                missions_sent: self.ids.sent,
                asks_made: self.asks_made,
                planned_ahead: self.planned_ahead.take(),
                track,
                fix,
                obstacles: self.obstacles.take(),
                resume: None,
            },
            position: self.here,
        }))
    }
}
