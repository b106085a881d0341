//! The APF controller on Zenoh: a thin adapter around [`Controller`], one per robot that
//! has been given a mission.
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/robot/*/mission` | subscription | `mission` (replaces the robot's mission) |
//! | `<root>/robot/*/estimate` | subscription | `position_estimate` (from localization) |
//! | `<root>/robot/<id>/cmd` | publication, one per estimate while a mission runs | `robot_command` |
//! | `<root>/robot/<id>/controller` | publication, per estimate and on state changes | `controller_status` |
//!
//! Robots without a mission are left alone (another driver may command them). The
//! obstacle map, the anchors and the sensing model come from the configured scenario,
//! like the localization service's.
//!
//! The robot is always the one the key names (a body that names another is refused). A
//! mission is taken at once for a robot the scenario has or localization reported within
//! `release_after_s`; one for any other robot waits, in a small bounded table, for that
//! robot's first estimate, so missions for robots that do not exist hold no slot.
//!
//! **Safety** (not in paper 002): a robot whose estimates stop for `stale_after_s` (wall
//! time) gets a zero command and the state `halted_stale`, repeated every
//! `stale_after_s / 4` until estimates return (after `release_after_s` the robot is
//! gone and its slot released); a PEB above the bound holds it
//! (`halted_peb`); no progress over the controller's window ends the mission as `stuck`.
//! The watchdog runs on wall time because a stalled estimate stream is exactly when sim
//! time stops being informative.

use roam_runtime::Delivery;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use roam_localization::fim::FimOptions;
use roam_localization::model::RangingModel;
use roam_proto::controller::{
    ControllerStatus, Mission, MissionState, MAX_MISSION_BYTES, MAX_MISSION_ID_BYTES, MAX_WAYPOINTS,
};
use roam_proto::localization::PositionEstimate;
use roam_proto::sim::RobotCommand;
use roam_proto::{excerpt, keys, Message};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::world_check::{self, WorldMismatch};
use roam_runtime::{limited_warn, routing, Service, ServiceError};
use roam_world::scenario::load_or_builtin;
use serde::Deserialize;
use tokio_util::sync::CancellationToken;

use crate::controller::{Controller, Decision, MissionStatus};
use crate::information::InformationField;
use crate::obstacle_field::ObstacleField;
use crate::params::ApfParams;

pub const SERVICE_NAME: &str = "controller";
/// Robots one controller instance drives at most.
pub const MAX_ROBOTS: usize = 1000;
/// Missions held for robots not yet heard of (see `ControllerShared::hold`).
pub const MAX_HELD_MISSIONS: usize = 64;
/// Largest estimate decoded, bytes (one is a few hundred).
pub const MAX_ESTIMATE_BYTES: usize = 64 * 1024;

/// The controller service's config file (YAML).
///
/// ```yaml
/// root: roam
/// scenario: config/scenarios/es1.yaml   # obstacles, anchors, sensing; default: built-in world
/// stale_after_s: 1.0                    # zero command when estimates stop this long
/// release_after_s: 30.0                 # forget a robot whose estimates stopped this long
/// robots: [r1]                          # drive only these robots; default: every robot
/// apf:                                  # paper 002 §4's values are the defaults
///   scheme: linear                      # plain | fixed | cutoff | linear | sinusoidal
///   z_is: 0.8
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControllerConfig {
    pub root: String,
    pub instance: Option<String>,
    pub scenario: Option<PathBuf>,
    pub stale_after_s: f64,
    /// A robot whose estimates have stopped this long (wall time; at least twice
    /// `stale_after_s`) is gone: its slot is released. A mission for a robot without an
    /// estimate this recent waits (at most [`MAX_HELD_MISSIONS`] of them, each this
    /// long) for the robot's first estimate, so missions for robots that do not exist
    /// never take a slot.
    pub release_after_s: f64,
    /// The robots this instance drives; empty: every robot that is given a mission. A
    /// controller on board a robot names its own, so it subscribes only to that robot's
    /// missions and estimates (nothing else crosses the robot's link) and never drives
    /// another robot when a fleet runs one controller per robot.
    pub robots: Vec<String>,
    pub apf: ApfParams,
    pub zenoh: Option<serde_json::Value>,
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig {
            root: keys::DEFAULT_ROOT.to_owned(),
            instance: None,
            scenario: None,
            stale_after_s: 1.0,
            release_after_s: 30.0,
            robots: Vec::new(),
            apf: ApfParams::default(),
            zenoh: None,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ControllerServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Scenario(#[from] roam_world::scenario::ScenarioError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error(transparent)]
    World(#[from] WorldMismatch),
}

/// One robot under control.
struct ControlledRobot {
    controller: Controller,
    mission: String,
    waypoints: usize,
    last_estimate: Instant,
    stale: bool,
    last: Option<ControllerStatus>,
}

/// What the controller's subscribers share: the session, the fields the controllers
/// steer by, and the robots under control.
struct ControllerShared {
    root: String,
    session: zenoh::Session,
    params: ApfParams,
    obstacles: Arc<ObstacleField>,
    information: Arc<InformationField>,
    stale_after: Duration,
    release_after: Duration,
    /// The robots this instance may drive; empty: any.
    allowed: Vec<String>,
    robots: Mutex<HashMap<String, ControlledRobot>>,
    /// The robots the scenario has: a mission for one is taken at once.
    scenario_robots: Vec<String>,
    /// When each robot's last estimate came (robots without a mission too), at most
    /// [`MAX_ROBOTS`]: with the scenario's robots, what "a robot the world has" means
    /// to the controller.
    seen: Mutex<HashMap<String, Instant>>,
    /// The step of each robot's last estimate answered, kept with `seen`.
    answered: Mutex<HashMap<String, u64>>,
    /// Missions decided on an estimate this controller has not answered yet
    /// ([`Mission::after_step`]), one per robot (the latest), for robots the world has:
    /// each starts once that estimate is answered.
    queued: Mutex<HashMap<String, Mission>>,
    /// Missions for robots not yet heard of, waiting for their first estimate: at most
    /// [`MAX_HELD_MISSIONS`], the oldest dropped first, each for `release_after`.
    held: Mutex<HashMap<String, (Instant, Mission)>>,
    /// Refused missions and estimates, logged a few per key and window.
    warnings: WarnLimiter,
}

impl ControllerShared {
    fn robots(&self) -> MutexGuard<'_, HashMap<String, ControlledRobot>> {
        roam_runtime::lock(&self.robots)
    }

    fn seen(&self) -> MutexGuard<'_, HashMap<String, Instant>> {
        roam_runtime::lock(&self.seen)
    }

    /// Notes an estimate of `robot`; when [`MAX_ROBOTS`] robots are noted, the one
    /// heard from longest ago makes room.
    fn note_seen(&self, robot: &str) {
        let mut seen = self.seen();
        if !seen.contains_key(robot) && seen.len() >= MAX_ROBOTS {
            if let Some(oldest) = seen.iter().min_by_key(|(_, t)| **t).map(|(r, _)| r.clone()) {
                seen.remove(&oldest);
            }
        }
        seen.insert(robot.to_owned(), Instant::now());
    }

    /// Whether `mission` waits for an estimate `robot`'s controller has not answered.
    fn waits(&self, robot: &str, mission: &Mission) -> bool {
        let Some(after) = mission.after_step else {
            return false;
        };
        roam_runtime::lock(&self.answered)
            .get(robot)
            .is_none_or(|answered| *answered < after)
    }

    /// The mission queued for `robot` if it may start before (`before: true`) or after
    /// answering the estimate of `step`.
    fn take_queued(&self, robot: &str, step: u64, before: bool) -> Option<Mission> {
        let mut queued = roam_runtime::lock(&self.queued);
        let after = queued.get(robot)?.after_step.unwrap_or(0);
        let due = if before { after < step } else { after <= step };
        if due {
            queued.remove(robot)
        } else {
            None
        }
    }

    /// Holds a mission until the robot's first estimate.
    fn hold(&self, robot: &str, mission: Mission) {
        let mut held = roam_runtime::lock(&self.held);
        if !held.contains_key(robot) && held.len() >= MAX_HELD_MISSIONS {
            if let Some(oldest) = held
                .iter()
                .min_by_key(|(_, (t, _))| *t)
                .map(|(r, _)| r.clone())
            {
                held.remove(&oldest);
            }
        }
        held.insert(robot.to_owned(), (Instant::now(), mission));
    }

    /// The mission held for `robot`, if one is and it has not expired.
    fn take_held(&self, robot: &str) -> Option<Mission> {
        let mut held = roam_runtime::lock(&self.held);
        let (at, mission) = held.remove(robot)?;
        (at.elapsed() < self.release_after).then_some(mission)
    }

    /// Whether the world has `robot`: the scenario names it, or localization reported
    /// it within `release_after`.
    fn is_present(&self, robot: &str) -> bool {
        self.scenario_robots.iter().any(|r| r == robot)
            || self
                .seen()
                .get(robot)
                .is_some_and(|t| t.elapsed() < self.release_after)
    }

    /// Commands, goals and statuses are state a robot must not miss: delivered.
    fn put<T: Message>(&self, key: &str, message: &T) {
        roam_runtime::publish_wait(&self.session, key, message, Delivery::Reliable);
    }

    fn command(&self, robot: &str, u: [f64; 2], step: Option<u64>) {
        self.put(
            &keys::robot_command(&self.root, robot),
            &RobotCommand { u, step },
        );
    }
}

fn status_of(
    robot: &str,
    driven: &ControlledRobot,
    decision: &Decision,
    estimate: Option<&PositionEstimate>,
) -> ControllerStatus {
    crate::status::controller_status(robot, &driven.mission, driven.waypoints, decision, estimate)
}

/// Checks a mission before it replaces the robot's current one.
fn check_mission(mission: &Mission) -> Result<(), String> {
    if mission.id.len() > MAX_MISSION_ID_BYTES {
        return Err(format!(
            "the id '{}' is {} bytes; at most {MAX_MISSION_ID_BYTES} (max_mission_id_bytes)",
            excerpt(&mission.id),
            mission.id.len()
        ));
    }
    if mission.waypoints.len() > MAX_WAYPOINTS {
        return Err(format!(
            "{} waypoints; a mission holds at most {MAX_WAYPOINTS} (max_waypoints)",
            mission.waypoints.len()
        ));
    }
    if let Some(bad) = mission
        .waypoints
        .iter()
        .find(|w| !(w[0].is_finite() && w[1].is_finite()))
    {
        return Err(format!("waypoint {bad:?} is not a finite point"));
    }
    Ok(())
}

fn on_mission(state: &ControllerShared, key: &str, mission: Mission) {
    let robot = match routing::robot_for(&state.root, key, &mission.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "mission refused: {e}"),
    };
    let id = excerpt(&mission.id);
    if let Err(e) = check_mission(&mission) {
        return limited_warn!(state.warnings, key, %robot, %id, "mission refused: {e}");
    }
    if !state.allowed.is_empty() && !state.allowed.iter().any(|r| r == robot) {
        return limited_warn!(
            state.warnings, key, %robot, %id,
            "mission refused: this controller drives only {:?} (robots)", state.allowed
        );
    }
    if !state.is_present(robot) {
        // Not in the scenario and not heard of yet (a robot just added to the sim, a
        // real robot before its first scan): the mission waits for the robot's first estimate, in a small table of its own,
        // so missions for robots that do not exist never take a driving slot.
        tracing::debug!(%robot, %id, "mission held until the robot's first estimate");
        state.hold(robot, mission);
        return;
    }
    if state.waits(robot, &mission) {
        // Decided on an estimate not answered yet: it starts once it is (the queue
        // holds one mission per robot the world has, the latest).
        roam_runtime::lock(&state.queued).insert(robot.to_owned(), mission);
        return;
    }
    roam_runtime::lock(&state.queued).remove(robot);
    install_mission(state, robot, &mission);
}

/// Makes `mission` the robot's current one and publishes its first status.
fn install_mission(state: &ControllerShared, robot: &str, mission: &Mission) {
    let mut robots = state.robots();
    if robots.len() >= MAX_ROBOTS && !robots.contains_key(robot) {
        return limited_warn!(
            state.warnings, robot, %robot,
            "mission refused: this controller already drives {MAX_ROBOTS} robots (max_robots)"
        );
    }
    let driven = robots
        .entry(robot.to_owned())
        .or_insert_with(|| ControlledRobot {
            controller: Controller::new(
                state.params.clone(),
                state.obstacles.clone(),
                state.information.clone(),
            ),
            mission: String::new(),
            waypoints: 0,
            last_estimate: Instant::now(),
            stale: false,
            last: None,
        });
    if mission.recovery {
        driven.controller.set_recovery(mission.waypoints.clone());
    } else {
        driven.controller.set_mission(mission.waypoints.clone());
    }
    driven.mission = mission.id.clone();
    driven.waypoints = mission.waypoints.len();
    driven.last_estimate = Instant::now();
    driven.stale = false;
    let state_now = if mission.waypoints.is_empty() {
        MissionState::Idle
    } else {
        MissionState::Active
    };
    let status = ControllerStatus {
        robot: robot.to_owned(),
        mission: Some(mission.id.clone()),
        state: state_now,
        waypoint: (!mission.waypoints.is_empty()).then_some(0),
        waypoints: driven.waypoints,
        distance_left_m: None,
        steps: 0,
        estimate_step: None,
        peb_m: None,
        omega_deg: 0.0,
        z_isa: 0.0,
        u: [0.0, 0.0],
    };
    driven.last = Some(status.clone());
    drop(robots);
    tracing::info!(%robot, id = %excerpt(&mission.id), waypoints = mission.waypoints.len(), "mission set");
    if mission.waypoints.is_empty() {
        // An empty mission stops the robot now, not at its next estimate.
        state.command(robot, [0.0, 0.0], None);
    }
    state.put(&keys::robot_controller(&state.root, robot), &status);
}

fn on_estimate(state: &ControllerShared, key: &str, estimate: PositionEstimate) {
    let robot = match routing::robot_for(&state.root, key, &estimate.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "ignoring an estimate: {e}"),
    };
    state.note_seen(robot);
    if let Some(mission) = state.take_held(robot) {
        install_mission(state, robot, &mission);
    }
    if let Some(mission) = state.take_queued(robot, estimate.step, true) {
        install_mission(state, robot, &mission);
    }
    roam_runtime::lock(&state.answered).insert(robot.to_owned(), estimate.step);
    let (status, u) = {
        let mut robots = state.robots();
        let Some(driven) = robots.get_mut(robot) else {
            return;
        };
        driven.last_estimate = Instant::now();
        driven.stale = false;
        let decision = driven.controller.update(estimate.position, estimate.peb_m);
        let status = status_of(robot, driven, &decision, Some(&estimate));
        driven.last = Some(status.clone());
        let u = match decision.status {
            MissionStatus::Idle => None,
            _ => Some(decision.u),
        };
        (status, u)
    };
    if let Some(u) = u {
        state.command(robot, u, Some(estimate.step));
    }
    state.put(&keys::robot_controller(&state.root, robot), &status);
    if let Some(mission) = state.take_queued(robot, estimate.step, false) {
        install_mission(state, robot, &mission);
    }
}

/// Holds every robot whose estimates have stopped: a zero command and `halted_stale`;
/// forgets a robot whose estimates have stopped for `release_after_s` (it is gone).
async fn watchdog(state: Arc<ControllerShared>, cancel: CancellationToken) {
    let tick = (state.stale_after / 4).max(Duration::from_millis(5));
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(tick) => {}
        }
        release_gone(&state);
        let halted: Vec<(String, ControllerStatus, bool)> = {
            let mut robots = state.robots();
            robots
                .iter_mut()
                .filter(|(_, d)| {
                    d.controller.is_active() && d.last_estimate.elapsed() >= state.stale_after
                })
                .filter_map(|(robot, d)| {
                    let first = !d.stale;
                    d.stale = true;
                    let mut status = d.last.clone()?;
                    status.state = MissionState::HaltedStale;
                    status.u = [0.0, 0.0];
                    Some((robot.clone(), status, first))
                })
                .collect()
        };
        for (robot, status, first) in halted {
            if first {
                tracing::warn!(%robot, "no estimate for {:?}: holding the robot", state.stale_after);
            }
            state.command(&robot, [0.0, 0.0], None);
            state.put(&keys::robot_controller(&state.root, &robot), &status);
        }
    }
}

/// Releases the slots of robots not heard from for `release_after`: a robot removed from
/// the world, or one that never was, stops costing a slot, commands and statuses.
fn release_gone(state: &ControllerShared) {
    let release_after = state.release_after;
    state.seen().retain(|_, t| t.elapsed() < release_after);
    roam_runtime::lock(&state.held).retain(|_, (t, _)| t.elapsed() < release_after);
    {
        let seen = state.seen();
        roam_runtime::lock(&state.answered).retain(|robot, _| seen.contains_key(robot));
    }
    let queued: Vec<String> = roam_runtime::lock(&state.queued).keys().cloned().collect();
    let gone: Vec<String> = queued
        .into_iter()
        .filter(|r| !state.is_present(r))
        .collect();
    if !gone.is_empty() {
        let mut queued = roam_runtime::lock(&state.queued);
        for robot in gone {
            queued.remove(&robot);
        }
    }
    state.robots().retain(|robot, d| {
        let keep = d.last_estimate.elapsed() < release_after;
        if !keep {
            tracing::info!(%robot, "no estimate for {release_after:?}: the robot is gone, its slot released");
        }
        keep
    });
}

/// Runs the controller service until `cancel` is cancelled.
pub async fn run(
    config: ControllerConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), ControllerServiceError> {
    config
        .apf
        .check()
        .map_err(|e| ControllerServiceError::Config(e.to_string()))?;
    if !(config.stale_after_s.is_finite() && config.stale_after_s > 0.0) {
        return Err(ControllerServiceError::Config(format!(
            "stale_after_s is {}; give a positive number of seconds",
            config.stale_after_s
        )));
    }
    if !(config.release_after_s.is_finite() && config.release_after_s > 0.0) {
        return Err(ControllerServiceError::Config(format!(
            "release_after_s is {}; give a positive number of seconds",
            config.release_after_s
        )));
    }
    for robot in &config.robots {
        keys::check_name("robot", robot)
            .map_err(|e| ControllerServiceError::Config(format!("robots: {e}")))?;
    }
    let (_, scenario) = load_or_builtin(config.scenario.as_deref())?;
    let anchors: Vec<[f64; 2]> = scenario.file.anchors.iter().map(|a| a.at).collect();
    let model = RangingModel::from_spec(&anchors, &scenario.file.sensing)
        .map_err(|e| ControllerServiceError::Config(format!("the scenario's sensing: {e}")))?;
    let information = Arc::new(InformationField::new(model, FimOptions::default()));
    let obstacles = Arc::new(ObstacleField::new(&scenario.occupancy));
    let mut service = Service::start(
        SERVICE_NAME,
        &config.root,
        config.instance.as_deref(),
        zenoh_config,
        cancel,
    )
    .await?;
    let world_guard = world_check::guard(&service, roam_world::world_id::of_scenario(&scenario));
    let state = Arc::new(ControllerShared {
        root: config.root.clone(),
        session: service.session().clone(),
        params: config.apf.clone(),
        obstacles,
        information,
        stale_after: Duration::from_secs_f64(config.stale_after_s),
        // A robot is gone only well after it is stale: a halted robot keeps its slot.
        release_after: Duration::from_secs_f64(
            config.release_after_s.max(2.0 * config.stale_after_s),
        ),
        allowed: config.robots.clone(),
        robots: Mutex::new(HashMap::new()),
        scenario_robots: scenario
            .file
            .robots
            .iter()
            .map(|r| r.name.clone())
            .collect(),
        seen: Mutex::new(HashMap::new()),
        held: Mutex::new(HashMap::new()),
        answered: Mutex::new(HashMap::new()),
        queued: Mutex::new(HashMap::new()),
        warnings: WarnLimiter::new(),
    });
    let (mission_keys, estimate_keys): (Vec<String>, Vec<String>) = if config.robots.is_empty() {
        (
            vec![keys::robot_mission_any(&config.root)],
            vec![keys::robot_estimate_any(&config.root)],
        )
    } else {
        config
            .robots
            .iter()
            .map(|r| {
                (
                    keys::robot_mission(&config.root, r),
                    keys::robot_estimate(&config.root, r),
                )
            })
            .unzip()
    };
    for key in &mission_keys {
        service
            .subscribe_with(
                key,
                MAX_MISSION_BYTES,
                state.clone(),
                |state: &Arc<ControllerShared>, key: &str, mission: Mission| {
                    on_mission(state, key, mission)
                },
            )
            .await?;
    }
    for key in &estimate_keys {
        service
            .subscribe_with(
                key,
                MAX_ESTIMATE_BYTES,
                state.clone(),
                |state: &Arc<ControllerShared>, key: &str, estimate: PositionEstimate| {
                    on_estimate(state, key, estimate)
                },
            )
            .await?;
    }
    let (watched, token) = (state.clone(), service.cancel_token());
    service.spawn(async move { watchdog(watched, token).await });
    service.announce().await?;
    service.run_until_stopped().await?;
    world_guard.outcome()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_config_is_the_indoor_controller() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/controller.yaml");
        let config: ControllerConfig = roam_runtime::config_file::load(&path).expect("parses");
        assert_eq!(config.apf, ApfParams::indoor());
        assert!(
            config.robots.is_empty(),
            "the shipped controller drives any robot"
        );
    }
}
