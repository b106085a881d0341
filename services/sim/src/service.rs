//! The sim world on Zenoh: a thin adapter around [`Sim`].
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/sim/control` | queryable | `sim_control` → `sim_status` |
//! | `<root>/sim/clock` | publication, every step | `sim_clock` |
//! | `<root>/robot/*/cmd` | subscription | `robot_command` (applies to the next step) |
//! | `<root>/robot/<id>/{ranges,observation,truth,events}` | publications, every step | `range_scan`, `observation`, `ground_truth`, `robot_events` |
//!
//! Two ways to run: free at a real-time factor (`resume`), or in lock-step, where each
//! `step` request runs n steps and answers once their messages are published. Commands
//! are taken by a callback subscriber the moment they arrive, so a command put before
//! a `step` request from the same session is in that step: lock-step runs are
//! reproducible through the service, bit for bit.

use roam_runtime::Delivery;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use roam_proto::sim::{
    ObjectsTruth, PendingCommand, RobotCommand, SimClock, SimControl, SimStatus,
};
use roam_proto::{decode, keys, ErrorCode, ErrorReply, Message};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::world_check::{self, WorldMismatch};
use roam_runtime::{reply, Service, ServiceError};
use roam_world::load_dirs::{Access, LoadDirs};
use roam_world::scenario::{self, ScenarioError};
use roam_world::DEFAULT_MAX_CELLS;
use serde::Deserialize;
use tokio::time::Instant;
use tokio_util::sync::CancellationToken;
use zenoh::query::Query;

use crate::messages::{points, robot_messages, RobotMessages};
use crate::semi_static::landed_truth;
use crate::sim::{Command, Sim, SimError};
use crate::snapshot::{self, SnapshotError};

pub const SERVICE_NAME: &str = "sim";
/// Steps one `step` request may ask for.
pub const MAX_STEPS_PER_REQUEST: u32 = 100_000;
/// Robot-steps (steps × robots) one `step` request may ask for: what bounds the work and
/// the messages one request causes, whatever the number of robots.
pub const MAX_ROBOT_STEPS_PER_REQUEST: u64 = 200_000;
/// The fastest real-time factor `resume` accepts (0 means as fast as possible).
pub const MAX_RATE: f64 = 1000.0;
/// The slowest real-time factor `resume` accepts: slower would leave minutes between
/// steps (a rate of 1e-6 once meant days).
pub const MIN_RATE: f64 = 0.01;
/// Largest control request, bytes.
pub const MAX_REQUEST_BYTES: usize = 64 * 1024;
/// Largest robot command, bytes (one is about 60).
pub const MAX_COMMAND_BYTES: usize = 1024;
/// How often a stepping sim writes its snapshot (wall time): what a crash can cost.
pub const SNAPSHOT_PERIOD: Duration = Duration::from_millis(500);

/// The sim service's config file (YAML).
///
/// ```yaml
/// root: roam
/// scenario: config/scenarios/es1.yaml   # default: the built-in downtime world
/// seed: 0
/// rate: 1.0                             # free-run at 1x; absent: start paused (lock-step)
/// state_file: /var/lib/roam/sim.json    # snapshot here; a restart resumes from it
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    pub root: String,
    pub instance: Option<String>,
    pub scenario: Option<PathBuf>,
    pub seed: u64,
    pub rate: Option<f64>,
    /// Where the sim keeps a snapshot of its clock and robots (every
    /// [`SNAPSHOT_PERIOD`] while it steps); at start it resumes from the snapshot when
    /// it is of the same scenario and seed. Absent: a restart begins at step 0.
    pub state_file: Option<PathBuf>,
    /// The directories a control `load` may read scenarios from (names relative to
    /// them; see `roam_world::load_dirs`). Empty: loads from the wire are off.
    pub load_dirs: Vec<PathBuf>,
    pub zenoh: Option<serde_json::Value>,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            root: keys::DEFAULT_ROOT.to_owned(),
            instance: None,
            scenario: None,
            seed: 0,
            rate: Some(1.0),
            state_file: None,
            load_dirs: Vec::new(),
            zenoh: None,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SimServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error("the scenario cannot be simulated: {0}")]
    Sim(#[from] SimError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error(transparent)]
    Snapshot(#[from] SnapshotError),
    #[error(transparent)]
    World(#[from] WorldMismatch),
}

/// The scenario as a status names it to any peer: its file name, never a path on the
/// sim's machine (the built-in world's name has no folder, so it stays as it is).
fn shown_name(scenario: &str) -> String {
    Path::new(scenario)
        .file_name()
        .map_or_else(|| scenario.to_owned(), |n| n.to_string_lossy().into_owned())
}

/// What control requests change.
struct Control {
    sim: Sim,
    scenario: String,
    running: bool,
    rate: f64,
    /// The latest command per robot, taken by the next step.
    pending: BTreeMap<String, RobotCommand>,
    late_steps: u64,
    free_steps: u64,
    /// The ids of the objects landed at the last `sim/objects` message: the next goes
    /// out when they differ.
    objects_published: Vec<u64>,
}

/// What the sim's control queryable, command subscriber and free run share.
struct SimShared {
    root: String,
    session: zenoh::Session,
    control: Mutex<Control>,
    load_dirs: LoadDirs,
    /// Held by whoever steps and publishes (the free run, one `step` request), so the
    /// messages of two steps never interleave and two lock-step drivers cannot pile up.
    stepper: tokio::sync::Mutex<()>,
    /// Held by the step request being served: a second one is told `busy` at once,
    /// while one that only meets the free run's last step (just paused) waits for it.
    step_request: tokio::sync::Mutex<()>,
    /// Woken by every control request, so the free run sees a pause, a new rate or a
    /// reset at once instead of after the sleep it was in.
    wake: tokio::sync::Notify,
    /// Refused commands, logged a few per robot and window.
    warnings: WarnLimiter,
}

impl SimShared {
    fn control(&self) -> MutexGuard<'_, Control> {
        roam_runtime::lock(&self.control)
    }

    fn status(&self) -> SimStatus {
        let c = self.control();
        let (robots, anchors) = points(&c.sim);
        SimStatus {
            scenario: shown_name(&c.scenario),
            seed: c.sim.seed(),
            step: c.sim.steps(),
            time_s: c.sim.time_s(),
            running: c.running,
            rate: c.rate,
            step_s: c.sim.params().time.step_s,
            late_steps: c.late_steps,
            free_steps: c.free_steps,
            robots,
            anchors,
            pending: c
                .pending
                .iter()
                .map(|(robot, command)| PendingCommand {
                    robot: robot.clone(),
                    step: command.step,
                })
                .collect(),
        }
    }
}

fn check_rate(rate: f64) -> Result<(), ErrorReply> {
    if rate == 0.0 || (rate.is_finite() && (MIN_RATE..=MAX_RATE).contains(&rate)) {
        Ok(())
    } else {
        Err(ErrorReply::new(
            ErrorCode::InvalidRequest,
            format!("rate {rate} is out of range; use 0 (as fast as possible) or {MIN_RATE} to {MAX_RATE} times real time"),
        ))
    }
}

/// Wall time between free-running steps at `rate` (0: none). The rate was checked, so
/// the period is at most `step_s / MIN_RATE`; a step_s the scenario check let through
/// cannot make it panic either.
fn step_period(step_s: f64, rate: f64) -> Duration {
    if rate > 0.0 {
        Duration::try_from_secs_f64(step_s / rate).unwrap_or(Duration::from_secs(60))
    } else {
        Duration::ZERO
    }
}

/// Runs the sim until `cancel` is cancelled.
pub async fn run(
    config: SimConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), SimServiceError> {
    if let Some(rate) = config.rate {
        check_rate(rate).map_err(|e| SimServiceError::Config(e.message))?;
    }
    let load_dirs =
        LoadDirs::new(&config.load_dirs).map_err(|e| SimServiceError::Config(e.to_string()))?;
    let (name, scenario) = scenario::load_or_builtin(config.scenario.as_deref())?;
    let mut sim = Sim::new(&scenario, config.seed)?;
    if let Some(path) = &config.state_file {
        resume_from(&mut sim, &name, config.seed, path)?;
    }
    let mut service = Service::start(
        SERVICE_NAME,
        &config.root,
        config.instance.as_deref(),
        zenoh_config,
        cancel,
    )
    .await?;
    let world_guard = world_check::guard(&service, roam_world::world_id::of_scenario(&scenario));
    let state = Arc::new(SimShared {
        root: config.root.clone(),
        session: service.session().clone(),
        control: Mutex::new(Control {
            sim,
            scenario: name,
            running: config.rate.is_some(),
            rate: config.rate.unwrap_or(1.0),
            pending: BTreeMap::new(),
            late_steps: 0,
            free_steps: 0,
            objects_published: Vec::new(),
        }),
        load_dirs,
        stepper: tokio::sync::Mutex::new(()),
        step_request: tokio::sync::Mutex::new(()),
        wake: tokio::sync::Notify::new(),
        warnings: WarnLimiter::new(),
    });

    // Commands: a callback, so a command is pending as soon as it arrives (the status names
    // it, for a lock-step driver: a command and a step request from another session
    // arrive in no promised order).
    let command_key = keys::robot_command_any(&config.root);
    let commands = {
        let state = state.clone();
        service
            .session()
            .declare_subscriber(&command_key)
            .callback(move |sample| {
                take_command(
                    &state,
                    sample.key_expr().as_str(),
                    &sample.payload().to_bytes(),
                )
            })
            .await
            .map_err(|e| ServiceError::Declare {
                what: "subscriber",
                key: command_key.clone(),
                reason: e.to_string(),
            })?
    };

    let control = service
        .declare_queryable(&keys::sim_control(&config.root))
        .await?;
    service.serve(control, state.clone(), |s, q| async move {
        answer_control(s, q).await
    });
    {
        let (state, cancel) = (state.clone(), service.cancel_token());
        service.spawn(async move { free_run(state, cancel).await });
    }
    if let Some(path) = config.state_file.clone() {
        let (state, cancel) = (state.clone(), service.cancel_token());
        service.spawn(async move { keep_snapshots(state, path, cancel).await });
    }
    service.announce().await?;
    service.cancelled().await;
    drop(commands);
    service
        .shutdown(roam_runtime::service::DEFAULT_GRACE)
        .await?;
    world_guard.outcome()?;
    Ok(())
}

/// Resumes `sim` from the snapshot at `path` when it is of this scenario and seed; a
/// snapshot of another run is left alone (and overwritten at the first save).
fn resume_from(sim: &mut Sim, name: &str, seed: u64, path: &Path) -> Result<(), SimServiceError> {
    let Some(saved) = snapshot::load(path)? else {
        return Ok(());
    };
    if saved.scenario != name || saved.seed != seed {
        tracing::warn!(
            path = %path.display(), scenario = %saved.scenario, seed = saved.seed,
            "the snapshot is of another scenario or seed: starting at step 0"
        );
        return Ok(());
    }
    sim.resume(&saved).map_err(|e| SnapshotError::Resume {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    tracing::info!(
        path = %path.display(), step = saved.step, robots = saved.robots.len(),
        "resumed from the snapshot"
    );
    Ok(())
}

/// Writes the snapshot every [`SNAPSHOT_PERIOD`] while the step count changes, and once
/// more at shutdown.
async fn keep_snapshots(state: Arc<SimShared>, path: PathBuf, cancel: CancellationToken) {
    let mut saved_step = None;
    loop {
        let stopping = tokio::select! {
            _ = cancel.cancelled() => true,
            _ = tokio::time::sleep(SNAPSHOT_PERIOD) => false,
        };
        let snap = {
            let c = state.control();
            c.sim.snapshot(&c.scenario)
        };
        if saved_step != Some(snap.step) {
            let target = path.clone();
            let step = snap.step;
            match tokio::task::spawn_blocking(move || snapshot::save(&target, &snap)).await {
                Ok(Ok(())) => saved_step = Some(step),
                Ok(Err(e)) => tracing::warn!("{e}"),
                Err(e) => tracing::warn!("the snapshot writer failed: {e}"),
            }
        }
        if stopping {
            return;
        }
    }
}

/// Stores a command for the next step; commands for unknown robots or with non-finite
/// values are dropped (logged), so the pending map never outgrows the robots.
fn take_command(state: &SimShared, key: &str, payload: &[u8]) {
    let Some(robot) = keys::robot_of(&state.root, key) else {
        return;
    };
    if payload.len() > MAX_COMMAND_BYTES {
        return roam_runtime::limited_warn!(
            state.warnings, robot, %robot, bytes = payload.len(),
            "dropping a command over {MAX_COMMAND_BYTES} bytes unread"
        );
    }
    let command = match decode::<RobotCommand>(payload) {
        Ok(c) if c.u.iter().all(|v| v.is_finite()) => c,
        Ok(c) => {
            return roam_runtime::limited_warn!(
                state.warnings, robot, %robot, u = ?c.u, "dropping a command that is not finite"
            )
        }
        Err(e) => {
            return roam_runtime::limited_warn!(
                state.warnings, robot, %robot, "dropping a command that does not decode: {e}"
            )
        }
    };
    let mut control = state.control();
    if control.sim.robot(robot).is_some() {
        control.pending.insert(robot.to_owned(), command);
    } else {
        tracing::debug!(%robot, "dropping a command for a robot the sim does not have");
    }
}

/// What one step has to publish once the lock is released.
struct Stepped {
    clock: SimClock,
    robots: Vec<RobotMessages>,
    /// The landed objects, when one landed or left in the step.
    objects: Option<ObjectsTruth>,
}

/// One step under the lock; returns the messages to publish after it is released.
fn step_once(state: &SimShared) -> Result<Stepped, ErrorReply> {
    let mut control = state.control();
    let commands: Vec<Command> = std::mem::take(&mut control.pending)
        .into_iter()
        .map(|(robot, c)| Command { robot, u: c.u })
        .collect();
    let report = control.sim.step(&commands).map_err(|e| sim_error(&e))?;
    let clock = SimClock {
        step: report.step,
        time_s: report.time_s,
    };
    let messages = report
        .robots
        .iter()
        .map(|r| robot_messages(&control.sim, report.step, report.time_s, r))
        .collect();
    let landed = landed_truth(control.sim.world().objects());
    let objects = (!landed
        .iter()
        .map(|o| o.id)
        .eq(control.objects_published.iter().copied()))
    .then(|| {
        control.objects_published = landed.iter().map(|o| o.id).collect();
        ObjectsTruth {
            step: report.step,
            time_s: report.time_s,
            objects: landed,
        }
    });
    Ok(Stepped {
        clock,
        robots: messages,
        objects,
    })
}

/// Every reading of a step is delivered: a robot's localization and controller run in
/// lock-step on them.
async fn put<T: Message>(state: &SimShared, key: &str, message: &T) {
    roam_runtime::publish(&state.session, key, message, Delivery::Reliable).await;
}

async fn publish(state: &SimShared, stepped: Stepped) {
    let root = &state.root;
    let Stepped {
        clock,
        robots,
        objects,
    } = stepped;
    if let Some(objects) = &objects {
        put(state, &keys::sim_objects(root), objects).await;
    }
    for m in robots {
        let robot = m.truth.robot.clone();
        put(state, &keys::robot_ranges(root, &robot), &m.ranges).await;
        put(state, &keys::robot_truth(root, &robot), &m.truth).await;
        if let Some(o) = &m.observation {
            put(state, &keys::robot_observation(root, &robot), o).await;
        }
        if let Some(e) = &m.events {
            put(state, &keys::robot_events(root, &robot), e).await;
        }
    }
    put(state, &keys::sim_clock(root), &clock).await;
}

/// Steps while running: every `step_s / rate` seconds of wall time, or back to back at
/// rate 0. A step whose messages are not out before the next one is due counts as late.
/// Every control request wakes it ([`SimShared::wake`]), so a pause, a reset or a new rate
/// takes effect at once, whatever the period was.
async fn free_run(state: Arc<SimShared>, cancel: CancellationToken) {
    let mut next = Instant::now();
    loop {
        let (running, period) = {
            let c = state.control();
            (c.running, step_period(c.sim.params().time.step_s, c.rate))
        };
        if !running {
            tokio::select! {
                _ = cancel.cancelled() => return,
                _ = state.wake.notified() => {}
                _ = tokio::time::sleep(Duration::from_millis(100)) => {}
            }
            next = Instant::now();
            continue;
        }
        {
            let _stepping = state.stepper.lock().await;
            if !state.control().running {
                continue;
            }
            match step_once(&state) {
                Ok(stepped) => publish(&state, stepped).await,
                Err(e) => tracing::warn!("step failed: {e}"),
            }
        }
        next += period;
        let now = Instant::now();
        {
            let mut c = state.control();
            c.free_steps += 1;
            if now > next {
                c.late_steps += 1;
            }
        }
        if now > next + period * 4 {
            // Far behind (a pause of the machine): catch up from now, not in a burst.
            next = now;
        }
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = state.wake.notified() => next = Instant::now(),
            _ = tokio::time::sleep_until(next) => {}
            _ = tokio::task::yield_now(), if period.is_zero() => {}
        }
    }
}

fn sim_error(e: &SimError) -> ErrorReply {
    let message = e.to_string();
    match e {
        SimError::UnknownRobot(_) => ErrorReply::new(ErrorCode::NotFound, message),
        SimError::TooManyRobots { max } => {
            ErrorReply::limit("max_robots", *max as u64, *max as u64 + 1, message)
        }
        _ => ErrorReply::new(ErrorCode::InvalidRequest, message),
    }
}

/// The reply to a peer's load of `requested`: refusals name the file as the peer gave
/// it, other errors name files relative to their load directory.
fn scenario_error(e: &ScenarioError, requested: &str, dirs: &LoadDirs) -> ErrorReply {
    let message = dirs.redact(&e.to_string());
    match e {
        ScenarioError::Refused(refused)
        | ScenarioError::Map {
            source: roam_world::ros_map::RosMapError::Refused(refused),
            ..
        } => refused.to_reply(requested),
        ScenarioError::Missing { .. } => ErrorReply::new(ErrorCode::NotFound, message),
        ScenarioError::Io { .. } => ErrorReply::new(ErrorCode::Internal, message),
        ScenarioError::Map { .. } => ErrorReply::new(ErrorCode::CorruptFile, message),
        _ => ErrorReply::new(ErrorCode::InvalidRequest, message),
    }
}

async fn answer_control(state: Arc<SimShared>, query: Query) {
    let request = match reply::decode_request::<SimControl>(&query, MAX_REQUEST_BYTES) {
        Ok(r) => r,
        Err(e) => return reply::send_error(&query, &e).await,
    };
    let outcome = control(&state, request).await;
    state.wake.notify_waiters();
    reply::send_result(&query, outcome.map(|()| state.status())).await;
}

/// Loads the scenario a peer named, relative to the load directories. A refusal is
/// logged with the server's paths, and answered with the file as the peer named it.
async fn load(state: &Arc<SimShared>, path: String, seed: u64) -> Result<(), ErrorReply> {
    let dirs = state.load_dirs.clone();
    let loaded = tokio::task::spawn_blocking(move || {
        let file = dirs
            .resolve(&path)
            .map_err(|e| (e.to_string(), e.to_reply(&path)))?;
        let scenario = scenario::load_with(&file, DEFAULT_MAX_CELLS, Access::Within(&dirs))
            .map_err(|e| (e.to_string(), scenario_error(&e, &path, &dirs)))?;
        let sim = Sim::new(&scenario, seed).map_err(|e| (e.to_string(), sim_error(&e)))?;
        Ok((file.display().to_string(), sim))
    })
    .await
    .unwrap_or_else(|e| {
        let reply = ErrorReply::new(ErrorCode::Internal, format!("loading failed: {e}"));
        Err((reply.to_string(), reply))
    });
    let (name, sim) = match loaded {
        Ok(loaded) => loaded,
        Err((detail, reply)) => {
            roam_runtime::limited_warn!(state.warnings, "load", %detail, "refused a scenario load");
            return Err(reply);
        }
    };
    let mut c = state.control();
    c.scenario = name;
    c.sim = sim;
    c.running = false;
    c.pending.clear();
    c.late_steps = 0;
    c.free_steps = 0;
    Ok(())
}

async fn control(state: &Arc<SimShared>, request: SimControl) -> Result<(), ErrorReply> {
    match request {
        SimControl::Load { path, seed } => load(state, path, seed).await?,
        SimControl::Reset { seed } => {
            let mut c = state.control();
            c.sim.reset(seed);
            c.pending.clear();
            c.late_steps = 0;
            c.free_steps = 0;
        }
        SimControl::Step { n } => {
            if n > MAX_STEPS_PER_REQUEST {
                return Err(ErrorReply::limit(
                    "max_steps_per_request",
                    u64::from(MAX_STEPS_PER_REQUEST),
                    u64::from(n),
                    format!("ask for at most {MAX_STEPS_PER_REQUEST} steps per request"),
                ));
            }
            let robots = state.control().sim.robots().count().max(1) as u64;
            let robot_steps = u64::from(n) * robots;
            if robot_steps > MAX_ROBOT_STEPS_PER_REQUEST {
                return Err(ErrorReply::limit(
                    "max_robot_steps_per_request",
                    MAX_ROBOT_STEPS_PER_REQUEST,
                    robot_steps,
                    format!(
                        "{n} steps of {robots} robots is {robot_steps} robot-steps; ask for at most {} steps per request",
                        MAX_ROBOT_STEPS_PER_REQUEST / robots
                    ),
                ));
            }
            let Ok(_request) = state.step_request.try_lock() else {
                return Err(ErrorReply::new(
                    ErrorCode::Busy,
                    "another step request is running; wait for its reply, then step again",
                ));
            };
            let _stepping = state.stepper.lock().await;
            if state.control().running {
                return Err(ErrorReply::new(
                    ErrorCode::InvalidRequest,
                    "the sim is free-running; pause it before stepping it in lock-step",
                ));
            }
            for _ in 0..n {
                if state.control().running {
                    break;
                }
                let stepped = step_once(state)?;
                publish(state, stepped).await;
            }
        }
        SimControl::Pause => state.control().running = false,
        SimControl::Resume { rate } => {
            check_rate(rate)?;
            let mut c = state.control();
            c.running = true;
            c.rate = rate;
            c.late_steps = 0;
            c.free_steps = 0;
        }
        SimControl::AddRobot { name, at } => {
            keys::check_name("robot name", &name)
                .map_err(|e| ErrorReply::new(ErrorCode::InvalidRequest, e.to_string()))?;
            state
                .control()
                .sim
                .add_robot(&name, at)
                .map_err(|e| sim_error(&e))?;
        }
        SimControl::RemoveRobot { name } => {
            let mut c = state.control();
            c.sim.remove_robot(&name).map_err(|e| sim_error(&e))?;
            c.pending.remove(&name);
        }
        SimControl::Status => {}
    }
    Ok(())
}
