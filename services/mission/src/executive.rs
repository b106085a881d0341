//! The mission executive on Zenoh: a client of the planner, the controller,
//! localization and the clock. One executive drives one robot through its tasks.
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/map/layer/{inflated,information}` | get, at start | `layer` (to thin paths and score them) |
//! | `<root>/planner/…/plan` | get, one per plan (a window's first, a replan, the next window's; a second only when a curious replan fails) | `plan_request` (`shortest: fallback`) → `plan` (with the shortest path) |
//! | `<root>/robot/<id>/mission` | put, per plan | `mission` (the thinned waypoints) |
//! | `<root>/robot/<id>/estimate` | subscription | `position_estimate` |
//! | `<root>/robot/<id>/controller` | subscription | `controller_status` |
//! | `<root>/sim/clock` | subscription | `sim_clock` (the mission clock; wall time without a sim) |
//!
//! The window's rules live in a plain state machine ([`crate::window`], with the replan
//! policy in [`crate::watch`]); this module is the thin async loop around it: it decodes
//! what it hears, feeds the machine, and performs its actions (plan requests, one per
//! plan; missions published; progress; the calibration's file).
//!
//! **Time.** Task start times are on the mission clock: sim seconds when a sim world
//! publishes its clock. The planner's deadline is wall time, so what planning costs on
//! the mission clock is the deadline times the clock's measured rate (a sim running at
//! 20× charges a 0.5 s plan 10 s of downtime); the driving budget t_exec is the time to
//! the task's start minus that.

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_planner::params::GaParams;
use roam_proto::controller::{ControllerStatus, Mission};
use roam_proto::keys;
use roam_proto::mission::ExecutiveStatus;
use roam_proto::planner::{Plan, PlannerModel};
use roam_runtime::{lock, ClientError, Delivery, Requester};
use tokio::task::JoinSet;
use tokio::time::MissedTickBehavior;
use tokio_util::sync::CancellationToken;

use crate::calibration::{path_measure, store, Calibration, CalibrationConfig, TimeModel};
use crate::information::InformationScale;
use crate::inputs::{listen, wait_for_world, Inputs};
use crate::request::plan_request;
use crate::tasks::Task;
pub use crate::window::WindowOutcome;
use crate::window::{
    DowntimeWindow, DrivenMission, Handover, Now, PlanAsk, WindowAction, WindowEvent, WindowRules,
    WindowSetup,
};

pub use crate::config::ExecutiveConfig;

pub use crate::error::ExecutiveError;

/// What the executive is doing, for a progress display.
#[derive(Debug, Clone, PartialEq)]
pub enum Progress {
    Planned {
        window: usize,
        task: String,
        budget_s: f64,
        eta_s: f64,
        curious: bool,
        /// The plan's probability of arriving late ([`crate::margin`]).
        late_probability: f64,
    },
    Replanned {
        window: usize,
        reason: String,
    },
    /// The PEB guard held the robot this long: it is driven back to its last fix.
    Recovering {
        window: usize,
        held_s: f64,
    },
    Arrived {
        window: usize,
        task: String,
        at_s: f64,
        start_s: f64,
    },
    GaveUp {
        window: usize,
        task: String,
    },
    /// The task was over before its window began: the executive was down through it
    /// (restarted after a crash). Nothing is driven or reported for it.
    Skipped {
        window: usize,
        task: String,
    },
    /// A plan came back: the model that made it and the wall seconds from the request
    /// to the answer (what a fleet's plan latency is measured by).
    Answered {
        window: usize,
        model: PlannerModel,
        took_s: f64,
    },
}

/// A curious plan is expected to take this times the slowest recent one, plus
/// [`PLAN_WALL_SLACK_S`].
const PLAN_WALL_MARGIN: f64 = 1.5;
const PLAN_WALL_SLACK_S: f64 = 0.05;

/// How long the executive waits for the sim's clock at its start.
const CLOCK_WAIT: Duration = Duration::from_secs(2);

/// How often the loop ticks: the watch's clock rules (give up, lost mission), the plan
/// retries and the end of the task.
const TICK: Duration = Duration::from_millis(20);

/// The executive on one robot while it runs its tasks: its Zenoh ends, and what it
/// keeps from window to window.
struct Executive<'a> {
    session: &'a zenoh::Session,
    root: &'a str,
    config: &'a ExecutiveConfig,
    planner: Arc<PlannerClient>,
    inputs: Inputs,
    /// The robot's last good estimate.
    position: Option<[f64; 2]>,
    /// The robot's time calibration, fitted as it drives.
    calibration: Calibration,
    /// Wall seconds the recent curious plans took (request to reply), the slowest.
    plan_wall_s: Option<f64>,
    /// What the last window handed the next (the arrival margin, the mission and ask
    /// counts, the next window's plan).
    handover: Handover,
    /// This executive's own tag in its mission ids (from its Zenoh session id), so a
    /// restarted executive never reuses an id its predecessor sent: the controller's
    /// statuses on an old mission are not taken for a new one's.
    tag: String,
    /// What it heard last, for its status.
    heard: Heard,
}

/// The sim steps of the last estimate and controller status the loop handled.
#[derive(Debug, Clone, Copy, Default)]
struct Heard {
    estimate_step: Option<u64>,
    status_step: Option<u64>,
}

/// A plan request's answer as the loop gets it back: the ask's id, whether it was
/// curious, the wall seconds it took, and the reply.
type Answered = (u64, bool, f64, Result<Plan, ClientError>);

impl Executive<'_> {
    fn now(&self) -> f64 {
        lock(&self.inputs.clock).now_s()
    }

    /// The model plans are made with: the fit, or Table I when not calibrating.
    fn time_model(&self) -> TimeModel {
        if self.config.calibrate {
            self.calibration.model()
        } else {
            TimeModel::table_i()
        }
    }

    /// What a curious plan costs on the mission clock: the config's fixed figure when
    /// it sets one, else the wall time the last ones took (with a margin; the deadline
    /// until one was measured) at the clock's rate. Charging the whole deadline would
    /// waste it whenever the GA ends sooner (its generations, on a small map).
    fn planning_cost_s(&self) -> f64 {
        if let Some(cost) = self.config.planning_cost_s {
            return cost;
        }
        let wall = self.plan_wall_s.map_or(self.config.plan_deadline_s, |w| {
            (w * PLAN_WALL_MARGIN + PLAN_WALL_SLACK_S).min(self.config.plan_deadline_s)
        });
        wall * lock(&self.inputs.clock).rate()
    }

    /// The machine's time: the mission clock, wall seconds since `began`, what a plan
    /// costs now, and the clock's rate.
    fn moment(&self, began: Instant) -> Now {
        Now {
            mission_s: self.now(),
            wall_s: began.elapsed().as_secs_f64(),
            planning_cost_s: self.planning_cost_s(),
            clock_rate: lock(&self.inputs.clock).rate(),
        }
    }

    /// Sends the request `ask` describes ([`plan_request`]) without waiting: its answer
    /// joins `in_flight`.
    fn ask(&self, ask: &PlanAsk, in_flight: &mut JoinSet<Answered>) {
        let request = plan_request(self.config, ask, self.time_model());
        let planner = self.planner.clone();
        let (id, curious) = (ask.id, ask.curious);
        in_flight.spawn(async move {
            let asked = Instant::now();
            let reply = planner.plan(&request).await;
            (id, curious, asked.elapsed().as_secs_f64(), reply)
        });
    }

    /// Learns what a curious plan costs from one that came back.
    fn took(&mut self, plan: &Plan, took_s: f64) {
        // Only what the GA took says what a curious plan costs (a fallback to the
        // shortest path is answered at once).
        if plan.model != PlannerModel::Shortest {
            // The slowest of the recent plans, forgetting slowly.
            self.plan_wall_s = Some(self.plan_wall_s.map_or(took_s, |w| took_s.max(0.8 * w)));
        }
    }

    /// Sends `mission`, decided on the last estimate heard: the controller starts it
    /// after answering that estimate ([`Mission::after_step`]), as the batch does.
    fn publish(&self, mission: &Mission) {
        let key = keys::robot_mission(self.root, &self.config.robot);
        let mission = Mission {
            after_step: self.heard.estimate_step,
            ..mission.clone()
        };
        roam_runtime::publish_wait(self.session, &key, &mission, Delivery::Reliable);
    }

    /// What the executive is doing, for operators and for lock-step drivers: the sim
    /// steps of the last estimate and controller status it handled, and the plans in
    /// flight.
    fn publish_status(&self, window: usize, asks: usize) {
        let heard = self.heard;
        let key = keys::robot_executive(self.root, &self.config.robot);
        let status = ExecutiveStatus {
            robot: self.config.robot.clone(),
            window,
            estimate_step: heard.estimate_step,
            status_step: heard.status_step,
            plans_in_flight: asks as u32,
        };
        roam_runtime::publish_wait(self.session, &key, &status, Delivery::Latest);
    }

    /// Waits briefly for the sim's clock, so that an executive restarted mid-mission
    /// sees the mission time and skips the tasks that ended while it was down. Without
    /// a sim (a real fleet on wall time) it goes on after the wait.
    async fn hear_the_clock(&self, cancel: &CancellationToken) -> Result<(), ExecutiveError> {
        let waited = Instant::now();
        while !lock(&self.inputs.clock).heard() && waited.elapsed() < CLOCK_WAIT {
            tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = tokio::time::sleep(Duration::from_millis(20)) => {}
            }
        }
        Ok(())
    }

    async fn first_position(
        &mut self,
        cancel: &CancellationToken,
    ) -> Result<[f64; 2], ExecutiveError> {
        if let Some(p) = self.position {
            return Ok(p);
        }
        let waited = Duration::from_secs(30);
        let deadline = tokio::time::sleep(waited);
        tokio::pin!(deadline);
        loop {
            tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = &mut deadline => {
                    return Err(ExecutiveError::NoEstimate { robot: self.config.robot.clone(), waited });
                }
                sample = self.inputs.estimates.recv_async() => {
                    let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                    if let Some(e) = self.inputs.estimate(&sample) {
                        self.heard.estimate_step = Some(e.step);
                        if !e.degraded {
                            self.position = Some(e.position);
                            // A sim that stepped for this estimate published its clock
                            // too: the window begins on the sim's time, not on wall time.
                            self.hear_the_clock(cancel).await?;
                            lock(&self.inputs.clock).heard_at(e.time_s);
                            return Ok(e.position);
                        }
                    }
                }
            }
        }
    }

    /// The calibration learns from the mission that arrived (its Σd and Σθ as Eq. 2
    /// counts them on the cells, and how long driving it took) and keeps the fit in the
    /// calibration file.
    fn calibrate(&mut self, window: usize, drive: &DrivenMission) {
        if !self.config.calibrate {
            return;
        }
        let (d, theta) = path_measure(&drive.path);
        if !self.calibration.add_planned(d, theta, drive.took_s) {
            return;
        }
        if let Some(path) = &self.config.calibration_file {
            if let Err(e) = store::save(path, &self.config.robot, &self.calibration) {
                tracing::warn!("{e}");
            }
        }
        let fitted = self.calibration.model();
        tracing::info!(
            window,
            v_lin = fitted.v_lin,
            v_ang = fitted.v_ang,
            took_s = drive.took_s,
            "time model updated from the window's driving"
        );
    }

    /// Window `window` toward `task`: the machine ([`DowntimeWindow`]) fed with what the
    /// executive hears, its actions performed in order; `None` when the task was over
    /// before the window began.
    async fn window(
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
        let handover = std::mem::replace(&mut self.handover, Handover::first(self.config.margin()));
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
                    WindowAction::Drive(mission) => self.publish(&mission),
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
                        reason: reason.as_str().to_owned(),
                    }),
                    WindowAction::Recovering { held_s } => {
                        progress(Progress::Recovering { window, held_s })
                    }
                    WindowAction::Arrived { at_s, drive } => {
                        progress(Progress::Arrived {
                            window,
                            task: name(),
                            at_s,
                            start_s: task.start_s,
                        });
                        self.calibrate(window, &drive);
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
                    Some(answered) = in_flight.join_next(), if !in_flight.is_empty() => {
                        let Ok((id, curious, took_s, reply)) = answered else { continue };
                        match reply {
                            Ok(plan) => {
                                self.took(&plan, took_s);
                                progress(Progress::Answered { window, model: plan.model, took_s });
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
                        WindowEvent::Estimate { position: e.position, peb_m: e.peb_m, degraded: e.degraded }
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

/// The robot's time calibration: from its file when one is configured and usable, else
/// Table I's prior.
fn load_calibration(config: &ExecutiveConfig) -> Result<Calibration, ExecutiveError> {
    let prior = config.time_model_prior;
    let settings = CalibrationConfig::default();
    let calibration = match &config.calibration_file {
        Some(path) => {
            let (calibration, loaded) = store::load(path, &config.robot, prior, settings)
                .map_err(|e| ExecutiveError::Config(e.to_string()))?;
            tracing::info!(path = %path.display(), ?loaded, model = ?calibration.model(), "time calibration");
            calibration
        }
        None => {
            Calibration::new(prior, settings).map_err(|e| ExecutiveError::Config(e.to_string()))?
        }
    };
    Ok(calibration)
}

/// Drives `config.robot` through its tasks and returns each window's outcome, calling
/// `on_window` as each one ends.
pub async fn run(
    session: &zenoh::Session,
    root: &str,
    config: &ExecutiveConfig,
    cancel: &CancellationToken,
    progress: &(dyn Fn(Progress) + Sync),
    on_window: &(dyn Fn(&WindowOutcome) + Sync),
) -> Result<Vec<WindowOutcome>, ExecutiveError> {
    config.check()?;
    let requester = Requester::new(session.clone(), Duration::from_secs(10));
    let world = wait_for_world(&requester, root, cancel).await?;
    // A day whose tasks are in walls or cannot be reached from each other in time is
    // refused before the robot moves, naming the tasks and the seconds missing.
    crate::day_check::check_day(&config.tasks, &world, config.time_model_prior, None)?;
    let params = GaParams::default();
    // The report's information is measured on the static map, as the driven path's: a
    // planner on the change coupling reports its own figure on the coupled map, which
    // changes with the mapper.
    let scale = InformationScale {
        world: &world,
        params: &params,
    };
    let inputs = listen(session, root, &config.robot).await?;
    let mut executive = Executive {
        session,
        root,
        config,
        // The robot's own plan keys: on a secure site its credentials reach no others.
        planner: Arc::new(PlannerClient::for_robot(
            session.clone(),
            root,
            &config.robot,
        )),
        inputs,
        position: None,
        calibration: load_calibration(config)?,
        plan_wall_s: None,
        handover: Handover::first(config.margin()),
        tag: session.zid().to_string().chars().take(8).collect(),
        heard: Heard::default(),
    };
    executive.hear_the_clock(cancel).await?;
    let mut outcomes = Vec::with_capacity(config.tasks.len());
    for (window, task) in config.tasks.iter().enumerate() {
        let next = config.tasks.get(window + 1);
        if let Some(outcome) = executive
            .window(window, task, next, scale, cancel, progress)
            .await?
        {
            on_window(&outcome);
            outcomes.push(outcome);
        }
    }
    Ok(outcomes)
}
