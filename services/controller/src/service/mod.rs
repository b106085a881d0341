//! The APF controller on Zenoh: a thin adapter around
//! [`Controller`](crate::controller::Controller), one per robot that has been given a
//! mission.
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

mod config;
mod estimates;
mod missions;
mod shared;
mod watchdog;

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use roam_localization::fim::FimOptions;
use roam_localization::model::RangingModel;
use roam_proto::controller::{Mission, MAX_MISSION_BYTES};
use roam_proto::keys;
use roam_proto::localization::PositionEstimate;
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::Service;
use roam_world::scenario::load_or_builtin;
use tokio_util::sync::CancellationToken;

use crate::information::InformationField;
use crate::obstacle_field::ObstacleField;

use estimates::on_estimate;
use missions::on_mission;
use shared::ControllerShared;
use watchdog::watchdog;

pub use config::{ControllerConfig, ControllerServiceError};
pub use shared::{MAX_HELD_MISSIONS, MAX_ROBOTS};

pub const SERVICE_NAME: &str = "controller";

/// Largest estimate decoded, bytes (one is a few hundred).
pub const MAX_ESTIMATE_BYTES: usize = 64 * 1024;

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
    let mut service = Service::start(SERVICE_NAME, &config.service, zenoh_config, cancel).await?;
    service.guard_world(roam_world::world_id::of_scenario(&scenario));
    let state = Arc::new(ControllerShared {
        root: config.service.root.clone(),
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
            vec![keys::robot_mission_any(&config.service.root)],
            vec![keys::robot_estimate_any(&config.service.root)],
        )
    } else {
        config
            .robots
            .iter()
            .map(|r| {
                (
                    keys::robot_mission(&config.service.root, r),
                    keys::robot_estimate(&config.service.root, r),
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
    Ok(())
}
