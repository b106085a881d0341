//! The mission executive on Zenoh: a client of the planner, the controller,
//! localization and the clock. One executive drives one robot through its tasks.
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/map/layer/{inflated,information}` | get, at start | `layer` (to thin paths and score them) |
//! | `<root>/planner/…/plan` | get, per window and replan | `plan_request` → `plan` |
//! | `<root>/robot/<id>/mission` | put, per plan | `mission` (the thinned waypoints) |
//! | `<root>/robot/<id>/estimate` | subscription | `position_estimate` |
//! | `<root>/robot/<id>/controller` | subscription | `controller_status` |
//! | `<root>/sim/clock` | subscription | `sim_clock` (the mission clock; wall time without a sim) |
//!
//! **Time.** Task start times are on the mission clock: sim seconds when a sim world
//! publishes its clock. The planner's deadline is wall time, so what planning costs on
//! the mission clock is the deadline times the clock's measured rate (a sim running at
//! 20× charges a 0.5 s plan 10 s of downtime); the driving budget t_exec is the time to
//! the task's start minus that.

use roam_runtime::Delivery;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_planner::params::GaParams;
use roam_planner::world::World;
use roam_proto::controller::{Mission, MissionState};
use roam_proto::keys;
use roam_proto::mission::{TimeModelReport, WindowReport};
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel};
use roam_runtime::{ClientError, Requester};
use serde::Deserialize;
use tokio_util::sync::CancellationToken;

use crate::calibration::{path_measure, store, Calibration, CalibrationConfig, TimeModel};
use crate::information::gathered;
use crate::inputs::{listen, wait_for_world, Inputs};
use crate::margin::ArrivalMargin;
use crate::path::{distance, mission_waypoints};
use crate::tasks::{self, Task, TaskError};
use crate::watch::{Decision, Reason, Status, Watch, WatchParams};
use roam_runtime::lock;

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

/// A window's outcome with the paths, for pictures.
#[derive(Debug, Clone)]
pub struct WindowOutcome {
    pub report: WindowReport,
    /// Every plan the robot was given in the window, in order.
    pub plans: Vec<Vec<[f64; 2]>>,
    /// The shortest path of the window, for comparison.
    pub shortest: Vec<[f64; 2]>,
    /// The estimates the robot drove on.
    pub driven: Vec<[f64; 2]>,
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

/// How often the executive asks again for a window's first plans when none came.
const PLAN_RETRY: Duration = Duration::from_secs(1);

/// A window's plans made ahead, while the robot did the previous task.
struct Preplanned {
    window: usize,
    from: [f64; 2],
    shortest: Plan,
    plan: Plan,
    budget: f64,
}

/// A preplanned window is used when the robot sets off at most this far from where the
/// plans start, metres.
const PREPLAN_FROM_M: f64 = 0.5;

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

/// The executive's view of one robot while it runs its tasks.
struct Run<'a> {
    session: &'a zenoh::Session,
    root: &'a str,
    config: &'a ExecutiveConfig,
    planner: PlannerClient,
    world: World,
    params: GaParams,
    inputs: Inputs,
    position: Option<[f64; 2]>,
    missions_sent: u64,
    /// The robot's time model, fitted as it drives.
    calibration: Calibration,
    /// Wall seconds the recent curious plans took (request to reply), the slowest.
    plan_wall_s: std::sync::Mutex<Option<f64>>,
    /// What each plan leaves unspent of the time to its task ([`crate::margin`]).
    margin: ArrivalMargin,
    /// The next window's plans, made while the robot did its task.
    preplanned: Option<Preplanned>,
    /// This executive's own tag in its mission ids (from its Zenoh session id), so a
    /// restarted executive never reuses an id its predecessor sent: the controller's
    /// statuses on an old mission are not taken for a new one's.
    tag: String,
}

impl Run<'_> {
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

    fn watch_params(&self) -> WatchParams {
        self.config.watch_params(self.time_model())
    }

    /// What a curious plan costs on the mission clock: the wall time the last ones
    /// took (with a margin; the deadline until one was measured) at the clock's rate.
    /// Charging the whole deadline would waste it whenever the GA ends sooner (its
    /// generations, on a small map): at a sim running 20x, a 1 s deadline is 20 s of
    /// downtime the robot would wait through.
    fn planning_cost_s(&self) -> f64 {
        let wall = lock(&self.plan_wall_s).map_or(self.config.plan_deadline_s, |w| {
            (w * PLAN_WALL_MARGIN + PLAN_WALL_SLACK_S).min(self.config.plan_deadline_s)
        });
        wall * lock(&self.inputs.clock).rate()
    }

    async fn plan(
        &self,
        from: [f64; 2],
        to: [f64; 2],
        model: PlannerModel,
        t_exec_s: f64,
    ) -> Result<Plan, ClientError> {
        let request = PlanRequest {
            request_id: None,
            cancel_token: None,
            start: from,
            goal: to,
            t_exec_s,
            deadline_s: self.config.plan_deadline_s,
            model,
            params: GaOverrides {
                max_generations: self.config.max_generations,
                w_loc: self.config.w_loc,
                ..self.time_model().overrides()
            },
            seed: self.config.seed,
            map_version: None,
        };
        let asked = Instant::now();
        let plan = self.planner.plan(&request).await?;
        if model != PlannerModel::Shortest {
            let took = asked.elapsed().as_secs_f64();
            let mut slowest = lock(&self.plan_wall_s);
            // The slowest of the recent plans, forgetting slowly.
            *slowest = Some(slowest.map_or(took, |w| took.max(0.8 * w)));
        }
        Ok(plan)
    }

    /// The curious plan for the budget, or the shortest when curiosity does not fit.
    /// `leave_at_s`: when the robot can set off at the earliest (a window planned while
    /// the robot is still at its task), on the mission clock.
    async fn plan_window(
        &self,
        from: [f64; 2],
        task: &Task,
        shortest: &Plan,
        curious: bool,
        leave_at_s: Option<f64>,
    ) -> Result<(Plan, f64), ClientError> {
        let earliest = self.now() + self.planning_cost_s();
        let time_left = task.start_s - leave_at_s.map_or(earliest, |at| at.max(earliest));
        let budget = self.margin.budget(time_left);
        if !curious || budget <= shortest.t_eta_s {
            return Ok((shortest.clone(), budget));
        }
        let plan = self.plan(from, task.at, self.config.model, budget).await?;
        if plan.reaches_goal && plan.within_budget {
            Ok((plan, budget))
        } else {
            Ok((shortest.clone(), budget))
        }
    }

    fn send(&mut self, window: usize, waypoints: Vec<[f64; 2]>) -> String {
        self.missions_sent += 1;
        let id = format!(
            "{}-{}-w{window}-m{}",
            self.config.robot, self.tag, self.missions_sent
        );
        let mission = Mission {
            robot: self.config.robot.clone(),
            id: id.clone(),
            waypoints,
        };
        let key = keys::robot_mission(self.root, &self.config.robot);
        roam_runtime::publish_wait(self.session, &key, &mission, Delivery::Reliable);
        id
    }

    fn waypoints(&self, plan: &Plan) -> Vec<[f64; 2]> {
        mission_waypoints(&plan.points, self.config.waypoint_spacing_m)
    }

    /// The window's shortest and curious plans, asked again every [`PLAN_RETRY`] while
    /// no planner answers (a router restart, every planner down); `None` when the
    /// window is given up meanwhile. An outage costs downtime, not the mission.
    async fn first_plans(
        &self,
        from: [f64; 2],
        task: &Task,
        leave_at_s: Option<f64>,
        cancel: &CancellationToken,
    ) -> Result<Option<(Plan, Plan, f64)>, ExecutiveError> {
        loop {
            let planned = match self
                .plan(from, task.at, PlannerModel::Shortest, 86_400.0)
                .await
            {
                Ok(shortest) => self
                    .plan_window(from, task, &shortest, true, leave_at_s)
                    .await
                    .map(|(plan, budget)| (shortest, plan, budget)),
                Err(e) => Err(e),
            };
            match planned {
                Ok(plans) => return Ok(Some(plans)),
                Err(e) => tracing::warn!(task = %task.name, "planning failed, asking again: {e}"),
            }
            if self.now() > task.start_s + self.config.give_up_after_s {
                return Ok(None);
            }
            tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = tokio::time::sleep(PLAN_RETRY) => {}
            }
        }
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

    /// What the window's last mission says about the time model: the plan it drove
    /// (its Σd and Σθ as Eq. 2 counts them on the cells) and how long driving it took.
    /// Reported against what `model` (the one the window was planned with) predicted;
    /// when calibrating, the fit learns from it and is kept in the calibration file.
    fn learn(
        &mut self,
        window: usize,
        model: &TimeModel,
        drive: Option<(&[[f64; 2]], f64)>,
        driving_s: f64,
        window_s: f64,
    ) -> TimeModelReport {
        let predicted_s = drive.map_or(0.0, |(points, _)| {
            let (d, theta) = path_measure(points);
            model.eta(d, theta)
        });
        if let Some((_, took_s)) = drive {
            self.margin.learn(predicted_s, took_s);
        }
        if let (true, Some((points, took_s))) = (self.config.calibrate, drive) {
            let (d, theta) = path_measure(points);
            if self.calibration.add_planned(d, theta, took_s) {
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
                    predicted_s,
                    took_s,
                    "time model updated from the window's driving"
                );
            }
        }
        TimeModelReport {
            v_lin: model.v_lin,
            v_ang: model.v_ang,
            predicted_s,
            driving_s: drive.map_or(0.0, |(_, t)| t),
            driven_share: if window_s > 0.0 {
                driving_s / window_s
            } else {
                0.0
            },
        }
    }

    async fn window(
        &mut self,
        window: usize,
        task: &Task,
        next: Option<&Task>,
        cancel: &CancellationToken,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<Option<WindowOutcome>, ExecutiveError> {
        // The first estimate comes through the router with the clock, so after it the
        // mission time is known even when the executive (re)started with the router down.
        let from = self.first_position(cancel).await?;
        let began = self.now();
        if began >= task.start_s + task.duration_s {
            progress(Progress::Skipped {
                window,
                task: task.name.clone(),
            });
            return Ok(None);
        }
        let preplanned = self
            .preplanned
            .take()
            .filter(|p| p.window == window && distance(p.from, from) <= PREPLAN_FROM_M);
        let planned = match preplanned {
            Some(p) => Some((p.shortest, p.plan, p.budget)),
            None => self.first_plans(from, task, None, cancel).await?,
        };
        let Some((shortest, plan, budget)) = planned else {
            // Given up before a plan came: reported like any window that was given up.
            progress(Progress::GaveUp {
                window,
                task: task.name.clone(),
            });
            let report = WindowReport {
                robot: self.config.robot.clone(),
                task: task.name.clone(),
                window,
                began_s: began,
                task_start_s: task.start_s,
                arrival_s: None,
                on_time: false,
                budget_s: task.start_s - began,
                planned_information: 0.0,
                driven_information: 0.0,
                shortest_information: 0.0,
                peb_mean_m: None,
                replans: 0,
                replan_reasons: vec!["no planner answered before the window was given up".into()],
                time_model: None,
            };
            return Ok(Some(WindowOutcome {
                report,
                plans: Vec::new(),
                shortest: Vec::new(),
                driven: vec![from],
            }));
        };
        progress(Progress::Planned {
            window,
            task: task.name.clone(),
            budget_s: budget,
            eta_s: plan.t_eta_s,
            curious: plan.model != PlannerModel::Shortest,
        });
        // On the static map, as the driven path's: a planner on the change coupling
        // reports its own figure on the coupled map, which changes with the mapper.
        let planned_information = gathered(&self.world, &self.params, &plan.points);
        let model = self.time_model();
        let mut plans = vec![plan.points.clone()];
        let mut waypoints = self.waypoints(&plan);
        let mut mission = self.send(window, waypoints.clone());
        let first_sent_at = self.now();
        let mut sent_at = first_sent_at;
        let mut current_path: Vec<[f64; 2]> = std::iter::once(from)
            .chain(plan.points.iter().copied())
            .collect();
        let wall = Instant::now();
        let wall_s = || wall.elapsed().as_secs_f64();
        let mut watch = Watch::new(
            self.watch_params(),
            task.start_s,
            plan.points.clone(),
            self.now(),
            wall_s(),
        );
        let mut driven = vec![from];
        let mut pebs = Vec::new();
        let mut reasons: Vec<String> = Vec::new();
        let mut arrival = None;
        let mut tick = tokio::time::interval(Duration::from_millis(100));
        loop {
            let decision = tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = tick.tick() => watch.on_tick(self.now(), wall_s()),
                sample = self.inputs.estimates.recv_async() => {
                    let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                    let Some(e) = self.inputs.estimate(&sample) else { continue };
                    if e.degraded {
                        continue;
                    }
                    self.position = Some(e.position);
                    driven.push(e.position);
                    if let Some(p) = e.peb_m {
                        pebs.push(p);
                    }
                    watch.on_estimate(e.position)
                }
                sample = self.inputs.statuses.recv_async() => {
                    let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                    let Some(s) = self.inputs.status(&sample) else { continue };
                    if s.mission.as_deref() != Some(mission.as_str()) {
                        continue;
                    }
                    let status = match s.state {
                        MissionState::Completed => Status::Completed,
                        MissionState::Stuck | MissionState::StepLimit => Status::Stuck,
                        MissionState::Active => Status::Active {
                            distance_left_m: s.distance_left_m.unwrap_or(0.0),
                        },
                        _ => Status::Other,
                    };
                    watch.on_status(status, self.now(), wall_s(), self.planning_cost_s())
                }
            };
            let (reason, curious, resend) = match decision {
                Decision::Keep => continue,
                Decision::Arrived { at_s } => {
                    arrival = Some(at_s);
                    progress(Progress::Arrived {
                        window,
                        task: task.name.clone(),
                        at_s,
                        start_s: task.start_s,
                    });
                    break;
                }
                Decision::GiveUp => {
                    progress(Progress::GaveUp {
                        window,
                        task: task.name.clone(),
                    });
                    break;
                }
                Decision::Replan {
                    reason,
                    curious,
                    resend,
                } => (reason, curious, resend),
            };
            if reason == Reason::Slack {
                // Slack pays for the robot waiting while it plans, so the new path
                // starts where the robot is rather than where it was.
                mission = self.send(window, Vec::new());
            }
            let here = self.position.unwrap_or(from);
            let shortest_here = match self
                .plan(here, task.at, PlannerModel::Shortest, 86_400.0)
                .await
            {
                Ok(p) => p,
                Err(e) => {
                    tracing::warn!("replanning failed: {e}");
                    if reason == Reason::Slack {
                        // Held for nothing: back on the path it had.
                        mission = self.send(window, waypoints.clone());
                    }
                    continue;
                }
            };
            // A curious plan that fails (busy, an outage) leaves the shortest way.
            let plan = match self
                .plan_window(here, task, &shortest_here, curious, None)
                .await
            {
                Ok((plan, _)) => plan,
                Err(e) => {
                    tracing::warn!("the curious replan failed, taking the shortest path: {e}");
                    shortest_here
                }
            };
            reasons.push(reason.as_str().to_owned());
            progress(Progress::Replanned {
                window,
                reason: reason.as_str().to_owned(),
            });
            let path = std::iter::once(here)
                .chain(plan.points.iter().copied())
                .collect();
            watch.replanned(path, resend, self.now(), wall_s());
            plans.push(plan.points.clone());
            waypoints = self.waypoints(&plan);
            mission = self.send(window, waypoints.clone());
            sent_at = self.now();
            current_path = std::iter::once(here)
                .chain(plan.points.iter().copied())
                .collect();
        }
        // The time model learns from the mission that arrived, driven as planned from
        // where it was sent (the path following keeps the robot on it).
        let drive = arrival.map(|at| (current_path.as_slice(), at - sent_at));
        let driving_s = arrival.map_or(0.0, |at| at - first_sent_at);
        let time_model = Some(self.learn(window, &model, drive, driving_s, task.start_s - began));
        // The next window is planned while the robot does this task, from its place,
        // so that planning costs the next window nothing.
        if let (Some(_), Some(next)) = (arrival, next) {
            let leave_at = task.start_s + task.duration_s;
            if let Ok(Some((shortest, plan, budget))) = self
                .first_plans(task.at, next, Some(leave_at), cancel)
                .await
            {
                if self.now() <= leave_at {
                    self.preplanned = Some(Preplanned {
                        window: window + 1,
                        from: task.at,
                        shortest,
                        plan,
                        budget,
                    });
                }
            }
        }
        // The task keeps the robot at its place until it ends.
        while arrival.is_some() && self.now() < task.start_s + task.duration_s {
            tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = tokio::time::sleep(Duration::from_millis(20)) => {}
            }
        }
        while self.inputs.estimates.try_recv().ok().flatten().is_some() {}
        let driven_information = gathered(&self.world, &self.params, &driven);
        let report = WindowReport {
            robot: self.config.robot.clone(),
            task: task.name.clone(),
            window,
            began_s: began,
            task_start_s: task.start_s,
            arrival_s: arrival,
            on_time: arrival.is_some_and(|a| a <= task.start_s),
            budget_s: budget,
            planned_information,
            driven_information,
            shortest_information: gathered(&self.world, &self.params, &shortest.points),
            peb_mean_m: (!pebs.is_empty()).then(|| pebs.iter().sum::<f64>() / pebs.len() as f64),
            replans: reasons.len() as u32,
            replan_reasons: reasons,
            time_model,
        };
        Ok(Some(WindowOutcome {
            report,
            plans,
            shortest: shortest.points,
            driven,
        }))
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
    let inputs = listen(session, root, &config.robot).await?;
    let mut run = Run {
        session,
        root,
        config,
        planner: PlannerClient::new(session.clone(), root),
        world,
        params: GaParams::default(),
        inputs,
        position: None,
        missions_sent: 0,
        calibration: load_calibration(config)?,
        plan_wall_s: std::sync::Mutex::new(None),
        margin: config.margin(),
        preplanned: None,
        tag: session.zid().to_string().chars().take(8).collect(),
    };
    run.hear_the_clock(cancel).await?;
    let mut outcomes = Vec::with_capacity(config.tasks.len());
    for (window, task) in config.tasks.iter().enumerate() {
        let next = config.tasks.get(window + 1);
        if let Some(outcome) = run.window(window, task, next, cancel, progress).await? {
            on_window(&outcome);
            outcomes.push(outcome);
        }
    }
    Ok(outcomes)
}
