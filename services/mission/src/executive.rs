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

use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_planner::params::GaParams;
use roam_planner::world::World;
use roam_proto::controller::{Mission, MissionState};
use roam_proto::mission::WindowReport;
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel};
use roam_proto::{encode, keys};
use roam_runtime::{ClientError, Requester};
use serde::Deserialize;
use tokio_util::sync::CancellationToken;
use zenoh::qos::CongestionControl;

use crate::information::gathered;
use crate::inputs::{listen, lock, wait_for_world, Inputs};
use crate::path::{eta_slips, mission_waypoints, off_path_m};
use crate::tasks::{self, Task, TaskError};

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
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(ExecutiveError::Config(format!(
                "{name} is {value}; give a positive number"
            )));
        }
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
    /// This executive's own tag in its mission ids (from its Zenoh session id), so a
    /// restarted executive never reuses an id its predecessor sent: the controller's
    /// statuses on an old mission are not taken for a new one's.
    tag: String,
}

impl Run<'_> {
    fn now(&self) -> f64 {
        lock(&self.inputs.clock).now_s()
    }

    /// What planning costs on the mission clock.
    fn planning_cost_s(&self) -> f64 {
        self.config.plan_deadline_s * lock(&self.inputs.clock).rate()
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
            start: from,
            goal: to,
            t_exec_s,
            deadline_s: self.config.plan_deadline_s,
            model,
            params: GaOverrides {
                max_generations: self.config.max_generations,
                w_loc: self.config.w_loc,
                ..GaOverrides::default()
            },
            seed: self.config.seed,
            map_version: None,
        };
        self.planner.plan(&request).await
    }

    /// The curious plan for the budget, or the shortest when curiosity does not fit.
    async fn plan_window(
        &self,
        from: [f64; 2],
        task: &Task,
        shortest: &Plan,
        curious: bool,
    ) -> Result<(Plan, f64), ClientError> {
        let budget = task.start_s - self.now() - self.planning_cost_s();
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
        if let Err(e) = zenoh::Wait::wait(
            self.session
                .put(&key, encode(&mission))
                .congestion_control(CongestionControl::Block),
        ) {
            tracing::warn!(%key, "sending the mission failed: {e}");
        }
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
        cancel: &CancellationToken,
    ) -> Result<Option<(Plan, Plan, f64)>, ExecutiveError> {
        loop {
            let planned = match self
                .plan(from, task.at, PlannerModel::Shortest, 86_400.0)
                .await
            {
                Ok(shortest) => self
                    .plan_window(from, task, &shortest, true)
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

    async fn window(
        &mut self,
        window: usize,
        task: &Task,
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
        let Some((shortest, plan, budget)) = self.first_plans(from, task, cancel).await? else {
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
        let planned_information = plan.distinct_information;
        let mut path = plan.points.clone();
        let mut plans = vec![plan.points.clone()];
        let mut mission = {
            let w = self.waypoints(&plan);
            self.send(window, w)
        };
        let mut driven = vec![from];
        let mut pebs = Vec::new();
        let mut reasons: Vec<String> = Vec::new();
        let mut resends = 0usize;
        let mut arrival = None;
        let mut slipped = false;
        let mut tick = tokio::time::interval(Duration::from_millis(100));
        let silence = Duration::from_secs_f64(self.config.controller_silence_s);
        let mut heard_at = Instant::now();
        loop {
            let mut replan: Option<(&'static str, bool)> = None;
            let mut resend = false;
            tokio::select! {
                _ = cancel.cancelled() => return Err(ExecutiveError::Cancelled),
                _ = tick.tick() => {
                    if self.now() > task.start_s + self.config.give_up_after_s {
                        progress(Progress::GaveUp { window, task: task.name.clone() });
                        break;
                    }
                    if heard_at.elapsed() >= silence {
                        heard_at = Instant::now();
                        resend = true;
                        replan = Some(("the controller went silent on the mission", !slipped));
                    }
                }
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
                    if off_path_m(e.position, &path) > self.config.off_path_m {
                        replan = Some(("pushed off the path", !slipped));
                    }
                }
                sample = self.inputs.statuses.recv_async() => {
                    let Ok(sample) = sample else { return Err(ExecutiveError::Cancelled) };
                    let Some(s) = self.inputs.status(&sample) else { continue };
                    if s.mission.as_deref() != Some(mission.as_str()) {
                        continue;
                    }
                    heard_at = Instant::now();
                    match s.state {
                        MissionState::Completed => {
                            let at_s = self.now();
                            arrival = Some(at_s);
                            progress(Progress::Arrived { window, task: task.name.clone(), at_s, start_s: task.start_s });
                            break;
                        }
                        MissionState::Stuck | MissionState::StepLimit => {
                            replan = Some(("stuck: the path is blocked", false));
                        }
                        MissionState::Active if !slipped => {
                            let left = s.distance_left_m.unwrap_or(0.0);
                            if eta_slips(self.now(), left, self.config.speed_m_per_s, task.start_s) {
                                slipped = true;
                                replan = Some(("the ETA slipped past the task's start", false));
                            }
                        }
                        _ => {}
                    }
                }
            }
            if let Some((reason, curious)) = replan {
                // A lost mission is always sent again (at most once per silence period);
                // the replan limit is for the robot's own trouble.
                let replans = reasons.len().saturating_sub(resends);
                if !resend && replans as u32 >= self.config.max_replans {
                    continue;
                }
                let here = self.position.unwrap_or(from);
                let shortest_here = match self
                    .plan(here, task.at, PlannerModel::Shortest, 86_400.0)
                    .await
                {
                    Ok(p) => p,
                    Err(e) => {
                        tracing::warn!("replanning failed: {e}");
                        continue;
                    }
                };
                // A curious plan that fails (busy, an outage) leaves the shortest way.
                let plan = match self.plan_window(here, task, &shortest_here, curious).await {
                    Ok((plan, _)) => plan,
                    Err(e) => {
                        tracing::warn!("the curious replan failed, taking the shortest path: {e}");
                        shortest_here
                    }
                };
                resends += usize::from(resend);
                reasons.push(reason.to_owned());
                progress(Progress::Replanned {
                    window,
                    reason: reason.to_owned(),
                });
                path = std::iter::once(here)
                    .chain(plan.points.iter().copied())
                    .collect();
                plans.push(plan.points.clone());
                let w = self.waypoints(&plan);
                mission = self.send(window, w);
                heard_at = Instant::now();
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
            shortest_information: shortest.distinct_information,
            peb_mean_m: (!pebs.is_empty()).then(|| pebs.iter().sum::<f64>() / pebs.len() as f64),
            replans: reasons.len() as u32,
            replan_reasons: reasons,
        };
        Ok(Some(WindowOutcome {
            report,
            plans,
            shortest: shortest.points,
            driven,
        }))
    }
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
        tag: session.zid().to_string().chars().take(8).collect(),
    };
    run.hear_the_clock(cancel).await?;
    let mut outcomes = Vec::with_capacity(config.tasks.len());
    for (window, task) in config.tasks.iter().enumerate() {
        if let Some(outcome) = run.window(window, task, cancel, progress).await? {
            on_window(&outcome);
            outcomes.push(outcome);
        }
    }
    Ok(outcomes)
}
