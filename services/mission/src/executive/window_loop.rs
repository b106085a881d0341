//! One window: the window machine fed with what the executive hears, its actions
//! performed in order.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use roam_proto::controller::ControllerStatus;
use roam_runtime::lock;
use tokio::task::JoinSet;
use tokio::time::MissedTickBehavior;
use tokio_util::sync::CancellationToken;

use crate::error::ExecutiveError;
use crate::information::InformationScale;
use crate::tasks::Task;
use crate::window::{
    DowntimeWindow, Handover, WindowAction, WindowEvent, WindowOutcome, WindowRules, WindowSetup,
};

use super::progress::Progress;
use super::robot::{Answered, Executive};

/// How often the loop ticks: the watch's clock rules (give up, lost mission), the plan
/// retries and the end of the task.
const TICK: Duration = Duration::from_millis(20);

impl Executive<'_> {
    /// Window `window` toward `task`: the machine ([`DowntimeWindow`]) fed with what the
    /// executive hears, its actions performed in order; `None` when the task was over
    /// before the window began.
    pub(super) async fn window(
        &mut self,
        window: usize,
        task: &Task,
        next: Option<&Task>,
        scale: InformationScale<'_>,
        cancel: &CancellationToken,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<Option<WindowOutcome>, ExecutiveError> {
        // The first estimate comes through the router with the clock, so after it the
        // mission time is known even when the executive (re)started with the router down.
        let from = self.first_position(cancel).await?;
        let began = Instant::now();
        let setup = WindowSetup {
            window,
            task: task.clone(),
            next: next.cloned(),
            robot: self.config.robot.clone(),
            mission_tag: self.tag.clone(),
            from,
            time_model: self.time_model(),
            watch: self.config.watch_params(self.time_model()),
            rules: WindowRules::of(self.config),
            give_up_after_s: self.config.give_up_after_s,
            waypoint_spacing_m: self.config.waypoint_spacing_m,
            scale,
        };
        let mut handover =
            std::mem::replace(&mut self.handover, Handover::first(self.config.margin()));
        if self.resume.as_ref().is_some_and(|r| r.task == task.name) {
            handover.resume = self.resume.take();
        }
        let (mut machine, actions) = DowntimeWindow::begin(setup, handover, self.moment(began));
        let mut pending = VecDeque::from(actions);
        // Dropping a request's future cancels it at the planner (PlannerClient::plan).
        let mut in_flight: JoinSet<Answered> = JoinSet::new();
        self.publish_status(window, machine.asks_in_flight());
        let mut tick = tokio::time::interval(TICK);
        tick.set_missed_tick_behavior(MissedTickBehavior::Delay);
        let name = || task.name.clone();
        // A controller status on an estimate not heard yet (it came first: the two
        // arrive on different links) waits for that estimate, so the window machine
        // meets them in the order the batch does: the estimate, then the status on it.
        let mut early_status: Option<ControllerStatus> = None;
        let mut released: Option<ControllerStatus> = None;
        loop {
            while let Some(action) = pending.pop_front() {
                match action {
                    WindowAction::Drive(mission) => {
                        self.publish(&mission);
                        self.keep_route(machine.driving());
                    }
                    WindowAction::RequestPlan(ask) => self.ask(&ask, &mut in_flight),
                    // The answer is dropped by the machine when it comes.
                    WindowAction::Forget(_) => {}
                    WindowAction::Planned {
                        budget_s,
                        eta_s,
                        curious,
                        late_probability,
                    } => progress(Progress::Planned {
                        window,
                        task: name(),
                        budget_s,
                        eta_s,
                        curious,
                        late_probability,
                    }),
                    WindowAction::Replanned { reason } => progress(Progress::Replanned {
                        window,
                        reason: reason.sentence().to_owned(),
                    }),
                    WindowAction::Recovering { held_s } => {
                        progress(Progress::Recovering { window, held_s })
                    }
                    WindowAction::Arrived { at_s, drives } => {
                        progress(Progress::Arrived {
                            window,
                            task: name(),
                            at_s,
                            start_s: task.start_s,
                        });
                        self.calibrate(window, &drives);
                    }
                    WindowAction::GaveUp => progress(Progress::GaveUp {
                        window,
                        task: name(),
                    }),
                    WindowAction::Skipped => progress(Progress::Skipped {
                        window,
                        task: name(),
                    }),
                    WindowAction::Done(end) => {
                        self.handover = end.handover;
                        self.position = Some(end.position);
                        // What was heard at the task is not the next window's drive.
                        while self.inputs.estimates.try_recv().ok().flatten().is_some() {}
                        return Ok(end.outcome);
                    }
                }
            }
            let event = if let Some(s) = released.take() {
                self.heard.status_step = s.estimate_step.or(self.heard.status_step);
                WindowEvent::Status(s)
            } else {
                tokio::select! {
                    _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                    _ = tick.tick() => WindowEvent::Tick,
                    Some(set) = changed_obstacles(&mut self.obstacles) => WindowEvent::MapChanged(set),
                    Some(answered) = in_flight.join_next(), if !in_flight.is_empty() => {
                        let Ok((id, curious, took_s, reply)) = answered else { continue };
                        match reply {
                            Ok(plan) => {
                                self.took(&plan, took_s);
                                let replan = plan.seed_route_used.is_some();
                                progress(Progress::Answered { window, model: plan.model, took_s, replan });
                                WindowEvent::PlanReply { id, plan: Box::new(plan) }
                            }
                            Err(e) => {
                                tracing::warn!(task = %task.name, curious, "the plan request failed: {e}");
                                WindowEvent::PlanFailed { id }
                            }
                        }
                    }
                    sample = self.inputs.estimates.recv_async() => {
                        let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                        let Some(e) = self.inputs.estimate(&sample) else { continue };
                        self.heard.estimate_step = Some(e.step);
                        if early_status.as_ref().is_some_and(|s| s.estimate_step <= Some(e.step)) {
                            released = early_status.take();
                        }
                        // The estimate's own time is on the mission clock only when that is the
                        // sim's; else (wall time) the window times it when heard.
                        let on_clock = lock(&self.inputs.clock).heard();
                        let time_s = if on_clock { e.time_s } else { f64::NAN };
                        WindowEvent::Estimate { position: e.position, peb_m: e.peb_m, degraded: e.degraded, time_s }
                    }
                    sample = self.inputs.statuses.recv_async() => {
                        let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                        let Some(s) = self.inputs.status(&sample) else { continue };
                        let ahead = s.estimate_step.is_some() && s.estimate_step > self.heard.estimate_step;
                        let s = if ahead {
                            // At most one waits: an older one goes now (its estimate was lost).
                            match early_status.replace(s) {
                                Some(older) => older,
                                None => continue,
                            }
                        } else {
                            s
                        };
                        self.heard.status_step = s.estimate_step.or(self.heard.status_step);
                        WindowEvent::Status(s)
                    }
                }
            };
            let tick_only = matches!(event, WindowEvent::Tick);
            pending.extend(machine.handle(event, self.moment(began)));
            if !tick_only {
                // A tick after every event: what the time decides (the task's end, the
                // last safe moment) is decided at the event's mission time, as in batch.
                pending.extend(machine.handle(WindowEvent::Tick, self.moment(began)));
                self.publish_status(window, machine.asks_in_flight());
            }
        }
    }
}

/// The next set of believed obstacles, when the executive follows them; pending forever
/// when it does not (or the follower stopped).
async fn changed_obstacles(
    sets: &mut Option<crate::obstacles::ObstacleSets>,
) -> Option<std::sync::Arc<crate::window::SeenObstacles>> {
    let Some(receiver) = sets else {
        return std::future::pending().await;
    };
    loop {
        if receiver.changed().await.is_err() {
            return std::future::pending().await;
        }
        if let Some(set) = receiver.borrow_and_update().clone() {
            return Some(set);
        }
    }
}
