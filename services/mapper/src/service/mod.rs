//! The change-rate mapper on Zenoh: a thin adapter around
//! [`ChangeMap`](crate::change_map::ChangeMap) and, for the robots it is told to drive,
//! [`Explorer`](crate::explorer::Explorer).
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/robot/*/observation` | subscription | `observation` (from the sim or a robot) |
//! | `<root>/robot/*/mission` | subscription | `mission` (a robot's current waypoints: its reservation) |
//! | `<root>/map/update/{change_rate,change_probability,change_information,recency,news,occupied_now}` | queries to the map server, throttled | `layer_update` |
//! | `<root>/robot/<id>/cmd` | publication, one per observation of a driven robot | `robot_command` |
//! | `<root>/robot/<id>/goal` | publication, when the learner picks a goal | `exploration_goal` |
//! | `<root>/mapper/status` | queryable | → `mapper_status` |
//!
//! The robot is the one the observation's key names; observation times are checked
//! against the sim clock, and a sim reset starts a new epoch ([`roam_world::epoch`]).
//!
//! Every robot's observations merge into one map. The layers are computed and sent at
//! most once per `publish_period_s` (wall time), and only when something was observed
//! (or a mission heard) since the last send: a map server is never flooded, whatever
//! the robots' rate.
//!
//! **Reservations.** Each robot's current mission (the waypoints the executive or a user
//! puts on `robot/<id>/mission`) is its reservation for the news value
//! ([`crate::news`]): the cells within the observation radius of the path from the
//! robot's last observed position through the waypoints, each at the time the robot
//! should leave it, driving from the mapper's time when the mission is heard (the newest
//! observation's) at `news.reserve.s_per_m` seconds per metre (paper 000's v_lin, 2 s/m
//! by default; the mission carries no times, and this needs no planner's time model). A
//! new mission replaces the robot's reservation, an empty one releases it; at most
//! [`MAX_RESERVING_ROBOTS`](crate::news::MAX_RESERVING_ROBOTS) robots hold one and a
//! reservation keeps the path's first [`MAX_RESERVED_CELLS`](crate::news::MAX_RESERVED_CELLS)
//! cells. The `news` layer counts every robot's reservation (no robot in particular), so
//! a robot's replan also sees its own plan as seen: a batch that plans per robot uses
//! [`NewsMap::news_scores`](crate::news::NewsMap::news_scores) with `for_robot`.

mod config;
mod layers;
mod missions;
mod observe;
mod shared;
mod status;

use std::collections::BTreeSet;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use roam_proto::controller::{Mission, MAX_MISSION_BYTES};
use roam_proto::keys;
use roam_proto::sim::{LocalObservation, SimClock};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::Service;
use roam_world::scenario::load_or_builtin;
use tokio_util::sync::CancellationToken;

use crate::change_map::MapParams;

use layers::publish_layers;
use missions::on_mission;
use observe::on_observation;
use shared::{MapperShared, MappingSpec};
use status::answer_status;

pub use config::{MapperConfig, MapperServiceError};

pub const SERVICE_NAME: &str = "mapper";
/// Robots the learner drives at most.
pub const MAX_EXPLORERS: usize = 64;
/// Largest observation decoded, bytes: a window of about three million cells.
pub const MAX_OBSERVATION_BYTES: usize = 4 * 1024 * 1024;
/// Largest sim clock decoded, bytes (one is about 60).
const MAX_CLOCK_BYTES: usize = 1024;

/// Runs the mapper until `cancel` is cancelled.
pub async fn run(
    config: MapperConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), MapperServiceError> {
    if !(config.publish_period_s.is_finite() && config.publish_period_s > 0.0) {
        return Err(MapperServiceError::Config(format!(
            "publish_period_s is {}; give a positive number of seconds",
            config.publish_period_s
        )));
    }
    let explore: BTreeSet<String> = config.explore.iter().cloned().collect();
    if explore.len() > MAX_EXPLORERS {
        return Err(MapperServiceError::Config(format!(
            "{} robots to explore with; at most {MAX_EXPLORERS} (max_explorers)",
            explore.len()
        )));
    }
    for robot in &explore {
        keys::check_name("robot", robot).map_err(|e| MapperServiceError::Config(e.to_string()))?;
    }
    for checked in [config.news.check(), config.belief.check()] {
        checked.map_err(|e| MapperServiceError::Config(e.to_string()))?;
    }
    let (_, scenario) = load_or_builtin(config.scenario.as_deref())?;
    let reserve_radius_m = config
        .news
        .reserve
        .radius_m
        .unwrap_or(scenario.file.sensing.observation_radius_m)
        .max(0.0);
    let spec = MappingSpec {
        map: MapParams {
            observation_period_s: scenario.file.time.step_s,
            ..config.map
        },
        news: config.news,
        explorer: config.explorer,
        seed: config.seed,
        explore,
    };
    let world = roam_world::world_id::of_scenario(&scenario);
    let mapping = spec.build(world.clone(), scenario.occupancy.clone())?;
    let mut service = Service::start(SERVICE_NAME, &config.service, zenoh_config, cancel).await?;
    service.guard_world(world);
    let state = Arc::new(MapperShared {
        root: config.service.root.clone(),
        session: service.session().clone(),
        mapping: Mutex::new(mapping),
        spec,
        belief: config.belief,
        reserve_radius_m,
        reserve_s_per_m: config.news.reserve.s_per_m,
        warnings: WarnLimiter::new(),
    });
    service
        .subscribe_with(
            &keys::sim_clock(&config.service.root),
            MAX_CLOCK_BYTES,
            state.clone(),
            |state: &Arc<MapperShared>, _key: &str, clock: SimClock| {
                state.mapping().epochs.on_clock(clock.time_s)
            },
        )
        .await?;
    service
        .subscribe_with(
            &keys::robot_observation_any(&config.service.root),
            MAX_OBSERVATION_BYTES,
            state.clone(),
            |state: &Arc<MapperShared>, key: &str, o: LocalObservation| {
                on_observation(state, key, o)
            },
        )
        .await?;
    service
        .subscribe_with(
            &keys::robot_mission_any(&config.service.root),
            MAX_MISSION_BYTES,
            state.clone(),
            |state: &Arc<MapperShared>, key: &str, mission: Mission| {
                on_mission(state, key, mission)
            },
        )
        .await?;
    let status_queryable = service
        .declare_queryable(&keys::mapper_status(&config.service.root))
        .await?;
    service.serve(status_queryable, state.clone(), |s, q| async move {
        answer_status(s, q).await
    });
    let (published, token) = (state.clone(), service.cancel_token());
    let period = Duration::from_secs_f64(config.publish_period_s);
    service.spawn(async move { publish_layers(published, period, token).await });
    service.announce().await?;
    service.run_until_stopped().await?;
    Ok(())
}
