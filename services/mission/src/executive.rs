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
use std::path::PathBuf;
use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_planner::params::GaParams;
use roam_proto::controller::Mission;
use roam_proto::keys;
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_runtime::{lock, ClientError, Delivery, Requester};
use serde::Deserialize;
use tokio::time::MissedTickBehavior;
use tokio_util::sync::CancellationToken;

use crate::calibration::{path_measure, store, Calibration, CalibrationConfig, TimeModel};
use crate::information::InformationScale;
use crate::inputs::{listen, wait_for_world, Inputs};
use crate::margin::ArrivalMargin;
use crate::tasks::{self, Task, TaskError};
use crate::watch::WatchParams;
pub use crate::window::WindowOutcome;
use crate::window::{
    DowntimeWindow, DrivenMission, Handover, Now, PlanAsk, WindowAction, WindowEvent, WindowSetup,
};

/// How the executive plans and watches.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExecutiveConfig {
    /// The robot this executive drives.
    pub robot: String,
    pub tasks: Vec<Task>,
    /// The curiosity model for downtime paths (paper 000).
    pub model: PlannerModel,
    /// The planner's deadline, wall seconds (paper 000's t_plan).
    pub plan_deadline_s: f64,
    /// Generations the GA may run at most (it stops at the deadline anyway).
    pub max_generations: Option<u32>,
    /// The planner's localizability cost W_loc (paper 002's PEB in paper 000's fitness;
    /// see the planner's `w_loc`). `None`: the planner's default, off.
    pub w_loc: Option<f64>,
    pub seed: u64,
    /// Waypoints are at most this far apart along the planned path, metres.
    pub waypoint_spacing_m: f64,
    /// An estimate farther than this from the planned path means the robot was pushed
    /// off it: replan from where it is, metres.
    pub off_path_m: f64,
    /// The robot's top speed for the ETA-slip check, m/s.
    pub speed_m_per_s: f64,
    /// Replans per window at most.
    pub max_replans: u32,
    /// A window is given up this long after its task's start, seconds.
    pub give_up_after_s: f64,
    /// No status from the controller on the current mission for this long (wall
    /// seconds) means the controller lost it (it restarted, or the robot's link was
    /// down when the mission was sent): replan from where the robot is and send again.
    pub controller_silence_s: f64,
    /// Arriving this much earlier than the task's start is slack: the executive replans
    /// a curious path from where the robot is with the time left (the mirror of the ETA
    /// slip rule), seconds. Infinity turns the rule off.
    pub slack_s: f64,
    /// Mission seconds between two slack replans at least.
    pub slack_interval_s: f64,
    /// What a plan leaves unspent of the time to the task: this share of it (or the
    /// robot's recent underestimate if more), and at least `arrival_margin_min_s`
    /// ([`crate::margin`]).
    pub arrival_margin_share: f64,
    pub arrival_margin_min_s: f64,
    /// Plan with paper 000 Eq. 2's v_lin and v_ang fitted to what this robot drove
    /// (Table I as the prior; see [`crate::calibration`]); `false`: Table I throughout.
    pub calibrate: bool,
    /// Where the robot's fit is kept across restarts; absent: in memory only.
    pub calibration_file: Option<PathBuf>,
    /// The time model before anything was driven (the calibration's prior): Table I's
    /// v_lin 2.0 s/m and v_ang 1.0 s/rad by default; a robot's datasheet figures where
    /// they are known. Bounded as the calibration's fits are.
    pub time_model_prior: TimeModel,
}

impl ExecutiveConfig {
    /// The replan policy's parameters for plans made with `model`.
    pub fn watch_params(&self, model: TimeModel) -> WatchParams {
        let expected = 1.0 / model.v_lin;
        WatchParams {
            off_path_m: self.off_path_m,
            speed_m_per_s: self.speed_m_per_s.min(expected),
            expected_speed_m_per_s: expected,
            max_replans: self.max_replans,
            give_up_after_s: self.give_up_after_s,
            controller_silence_s: self.controller_silence_s,
            slack_s: self.slack_s,
            slack_interval_s: self.slack_interval_s,
            behind: true,
        }
    }

    /// The arrival margin this config asks for ([`crate::margin`]).
    pub fn margin(&self) -> ArrivalMargin {
        ArrivalMargin::new(self.arrival_margin_share, self.arrival_margin_min_s)
    }
}

impl Default for ExecutiveConfig {
    fn default() -> Self {
        ExecutiveConfig {
            robot: "robot".to_owned(),
            tasks: tasks::builtin(),
            model: PlannerModel::Model1,
            plan_deadline_s: 1.0,
            max_generations: Some(1000),
            w_loc: None,
            seed: 0,
            waypoint_spacing_m: 1.0,
            off_path_m: 1.5,
            speed_m_per_s: 0.5,
            max_replans: 5,
            give_up_after_s: 60.0,
            controller_silence_s: 3.0,
            slack_s: 10.0,
            slack_interval_s: 10.0,
            arrival_margin_share: 0.08,
            arrival_margin_min_s: 2.0,
            calibrate: true,
            calibration_file: None,
            time_model_prior: TimeModel::table_i(),
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ExecutiveError {
    #[error(transparent)]
    Tasks(#[from] TaskError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error(transparent)]
    Client(#[from] ClientError),
    #[error("the map server's {0} layer is not usable: {1}")]
    Layer(&'static str, String),
    #[error("no estimate of robot {robot:?} within {waited:?}: is localization running and the robot in range of the anchors?")]
    NoEstimate { robot: String, waited: Duration },
    #[error("zenoh: {0}")]
    Zenoh(String),
    #[error("stopped")]
    Cancelled,
}

/// What the executive is doing, for a progress display.
#[derive(Debug, Clone, PartialEq)]
pub enum Progress {
    Planned {
        window: usize,
        task: String,
        budget_s: f64,
        eta_s: f64,
        curious: bool,
    },
    Replanned {
        window: usize,
        reason: String,
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
}

/// A curious plan is expected to take this times the slowest recent one, plus
/// [`PLAN_WALL_SLACK_S`].
const PLAN_WALL_MARGIN: f64 = 1.5;
const PLAN_WALL_SLACK_S: f64 = 0.05;

/// How long the executive waits for the sim's clock at its start.
const CLOCK_WAIT: Duration = Duration::from_secs(2);

fn check(config: &ExecutiveConfig) -> Result<(), ExecutiveError> {
    tasks::check(&config.tasks)?;
    keys::check_name("robot", &config.robot).map_err(|e| ExecutiveError::Config(e.to_string()))?;
    for (name, value) in [
        ("plan_deadline_s", config.plan_deadline_s),
        ("waypoint_spacing_m", config.waypoint_spacing_m),
        ("off_path_m", config.off_path_m),
        ("speed_m_per_s", config.speed_m_per_s),
        ("give_up_after_s", config.give_up_after_s),
        ("controller_silence_s", config.controller_silence_s),
        ("slack_interval_s", config.slack_interval_s),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(ExecutiveError::Config(format!(
                "{name} is {value}; give a positive number"
            )));
        }
    }
    if !(0.0..0.5).contains(&config.arrival_margin_share) {
        return Err(ExecutiveError::Config(format!(
            "arrival_margin_share is {}; give a share in 0..0.5 of the time to the task",
            config.arrival_margin_share
        )));
    }
    if !(config.arrival_margin_min_s.is_finite() && config.arrival_margin_min_s >= 0.0) {
        return Err(ExecutiveError::Config(format!(
            "arrival_margin_min_s is {}; give 0 or more seconds",
            config.arrival_margin_min_s
        )));
    }
    if config.slack_s.is_nan() || config.slack_s <= 0.0 {
        return Err(ExecutiveError::Config(format!(
            "slack_s is {}; give a positive number of seconds (.inf turns the slack rule off)",
            config.slack_s
        )));
    }
    Ok(())
}

/// How often the loop ticks: the watch's clock rules (give up, lost mission), the plan
/// retries and the end of the task.
const TICK: Duration = Duration::from_millis(20);

/// The executive on one robot while it runs its tasks: its Zenoh ends, and what it
/// keeps from window to window.
struct Executive<'a> {
    session: &'a zenoh::Session,
    root: &'a str,
    config: &'a ExecutiveConfig,
    planner: PlannerClient,
    inputs: Inputs,
    /// The robot's last good estimate.
    position: Option<[f64; 2]>,
    /// The robot's time model, fitted as it drives.
    calibration: Calibration,
    /// Wall seconds the recent curious plans took (request to reply), the slowest.
    plan_wall_s: Option<f64>,
    /// What the last window handed the next (the arrival margin, the mission count, the
    /// next window's plan).
    handover: Handover,
    /// This executive's own tag in its mission ids (from its Zenoh session id), so a
    /// restarted executive never reuses an id its predecessor sent: the controller's
    /// statuses on an old mission are not taken for a new one's.
    tag: String,
}

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

    /// What a curious plan costs on the mission clock: the wall time the last ones
    /// took (with a margin; the deadline until one was measured) at the clock's rate.
    /// Charging the whole deadline would waste it whenever the GA ends sooner (its
    /// generations, on a small map): at a sim running 20x, a 1 s deadline is 20 s of
    /// downtime the robot would wait through.
    fn planning_cost_s(&self) -> f64 {
        let wall = self.plan_wall_s.map_or(self.config.plan_deadline_s, |w| {
            (w * PLAN_WALL_MARGIN + PLAN_WALL_SLACK_S).min(self.config.plan_deadline_s)
        });
        wall * lock(&self.inputs.clock).rate()
    }

    /// The machine's time: the mission clock, wall seconds since `began`, and what a
    /// plan costs now.
    fn moment(&self, began: Instant) -> Now {
        Now {
            mission_s: self.now(),
            wall_s: began.elapsed().as_secs_f64(),
            planning_cost_s: self.planning_cost_s(),
        }
    }

    /// One request for the plan `ask` describes, with the shortest path as its fallback
    /// and attached ([`crate::window`]'s one-request rule).
    async fn plan(&mut self, ask: &PlanAsk) -> Result<Plan, ClientError> {
        let request = PlanRequest {
            request_id: None,
            cancel_token: None,
            start: ask.from,
            goal: ask.to,
            t_exec_s: ask.t_exec_s,
            deadline_s: self.config.plan_deadline_s,
            model: if ask.curious {
                self.config.model
            } else {
                PlannerModel::Shortest
            },
            params: GaOverrides {
                max_generations: self.config.max_generations,
                w_loc: self.config.w_loc,
                ..self.time_model().overrides()
            },
            seed: self.config.seed,
            map_version: None,
            shortest: ShortestPathUse::Fallback,
        };
        let asked = Instant::now();
        let plan = self.planner.plan(&request).await?;
        // Only what the GA took says what a curious plan costs (a fallback to the
        // shortest path is answered at once).
        if plan.model != PlannerModel::Shortest {
            let took = asked.elapsed().as_secs_f64();
            // The slowest of the recent plans, forgetting slowly.
            self.plan_wall_s = Some(self.plan_wall_s.map_or(took, |w| took.max(0.8 * w)));
        }
        Ok(plan)
    }

    fn publish(&self, mission: &Mission) {
        let key = keys::robot_mission(self.root, &self.config.robot);
        roam_runtime::publish_wait(self.session, &key, mission, Delivery::Reliable);
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
                        if !e.degraded {
                            self.position = Some(e.position);
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
            give_up_after_s: self.config.give_up_after_s,
            waypoint_spacing_m: self.config.waypoint_spacing_m,
            scale,
        };
        let handover = std::mem::replace(&mut self.handover, Handover::first(self.config.margin()));
        let (mut machine, actions) = DowntimeWindow::begin(setup, handover, self.moment(began));
        let mut pending = VecDeque::from(actions);
        let mut tick = tokio::time::interval(TICK);
        tick.set_missed_tick_behavior(MissedTickBehavior::Delay);
        let name = || task.name.clone();
        loop {
            while let Some(action) = pending.pop_front() {
                match action {
                    WindowAction::Drive(mission) | WindowAction::Hold(mission) => {
                        self.publish(&mission)
                    }
                    WindowAction::RequestPlan(ask) => {
                        let event = tokio::select! {
                            _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                            reply = self.plan(&ask) => match reply {
                                Ok(plan) => WindowEvent::PlanReply(Box::new(plan)),
                                Err(e) => {
                                    tracing::warn!(task = %task.name, curious = ask.curious, "the plan request failed: {e}");
                                    WindowEvent::PlanFailed
                                }
                            },
                        };
                        pending.extend(machine.handle(event, self.moment(began)));
                    }
                    WindowAction::Planned {
                        budget_s,
                        eta_s,
                        curious,
                    } => progress(Progress::Planned {
                        window,
                        task: name(),
                        budget_s,
                        eta_s,
                        curious,
                    }),
                    WindowAction::Replanned { reason } => progress(Progress::Replanned {
                        window,
                        reason: reason.as_str().to_owned(),
                    }),
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
            let event = tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = tick.tick() => WindowEvent::Tick,
                sample = self.inputs.estimates.recv_async() => {
                    let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                    let Some(e) = self.inputs.estimate(&sample) else { continue };
                    WindowEvent::Estimate { position: e.position, peb_m: e.peb_m, degraded: e.degraded }
                }
                sample = self.inputs.statuses.recv_async() => {
                    let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                    let Some(s) = self.inputs.status(&sample) else { continue };
                    WindowEvent::Status(s)
                }
            };
            pending.extend(machine.handle(event, self.moment(began)));
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
    check(config)?;
    let requester = Requester::new(session.clone(), Duration::from_secs(10));
    let world = wait_for_world(&requester, root, cancel).await?;
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
        planner: PlannerClient::new(session.clone(), root),
        inputs,
        position: None,
        calibration: load_calibration(config)?,
        plan_wall_s: None,
        handover: Handover::first(config.margin()),
        tag: session.zid().to_string().chars().take(8).collect(),
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
