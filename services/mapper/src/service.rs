//! The change-rate mapper on Zenoh: a thin adapter around [`ChangeMap`] and, for the
//! robots it is told to drive, [`Explorer`].
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
//! [`MAX_RESERVING_ROBOTS`] robots hold one and a reservation keeps the path's first
//! [`MAX_RESERVED_CELLS`] cells. The `news` layer counts every robot's reservation (no
//! robot in particular), so a robot's replan also sees its own plan as seen: a batch
//! that plans per robot uses [`NewsMap::news_scores`] with `for_robot`.

use roam_runtime::Delivery;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use roam_proto::cells::Cells;
use roam_proto::map::{
    GridMeta, Layer, LayerChange, LayerList, LayerUpdate, Origin, UpdateAck, OCCUPANCY_LAYER,
};

use roam_proto::controller::{Mission, MAX_MISSION_BYTES};
use roam_proto::mapper::{
    ExplorationGoal, ExplorerStatus, MapperStatus, ReservationStatus, CHANGE_INFORMATION_LAYER,
    CHANGE_PROBABILITY_LAYER, CHANGE_RATE_LAYER, NEWS_LAYER, OCCUPIED_NOW_LAYER, RECENCY_LAYER,
};
use roam_proto::sim::{LocalObservation, RobotCommand, SimClock};
use roam_proto::{keys, ErrorReply, Message};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::world_check::{self, WorldMismatch};
use roam_runtime::{limited_warn, reply, routing, Requester, Service, ServiceError};
use roam_world::grid::Grid;
use roam_world::scenario::load_or_builtin;
use serde::Deserialize;
use tokio_util::sync::CancellationToken;
use zenoh::query::Query;

use crate::belief::{occupied_now, BeliefParams};
use crate::change_map::{ChangeMap, MapParams, ObservationWindow};
use crate::explorer::{Explorer, ExplorerParams, Mode};
use crate::news::{NewsMap, NewsParams, MAX_RESERVED_CELLS, MAX_RESERVING_ROBOTS};
use crate::reserve::cells_along;
use roam_world::epoch::Epochs;

pub const SERVICE_NAME: &str = "mapper";
/// Robots the learner drives at most.
pub const MAX_EXPLORERS: usize = 64;
/// Largest observation decoded, bytes: a window of about three million cells.
pub const MAX_OBSERVATION_BYTES: usize = 4 * 1024 * 1024;
/// Largest sim clock decoded, bytes (one is about 60).
const MAX_CLOCK_BYTES: usize = 1024;

/// The mapper's config file (YAML).
///
/// ```yaml
/// root: roam
/// scenario: config/scenarios/grid004.yaml   # the map the layers cover; default: built-in world
/// explore: [robot]                          # robots the curious learner drives (default none)
/// publish_period_s: 1.0                     # the layers go to the map server at most this often
/// seed: 0
/// news:                                     # the news value (crate::news)
///   prior: { alpha: 1.0, beta_s: 3600.0 }  # λ̂ = (c + α)/(S + β), news.rs
///   reserve: { s_per_m: 2.0 }               # radius_m: default the scenario's observation radius
/// belief:                                   # the map now (crate::belief)
///   prior: { alpha: 0.0001, beta_s: 60.0 }
///   unseen_occupied: 0.5                    # a cell never seen where the static map has no value
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapperConfig {
    pub root: String,
    pub instance: Option<String>,
    pub scenario: Option<PathBuf>,
    pub explore: Vec<String>,
    pub publish_period_s: f64,
    pub seed: u64,
    pub explorer: ExplorerParams,
    /// The map's parameters; `observation_period_s` is taken from the scenario's step.
    pub map: MapParams,
    /// The news value's prior and how missions become reservations.
    pub news: NewsParams,
    /// The map now's prior.
    pub belief: BeliefParams,
    pub zenoh: Option<serde_json::Value>,
}

impl Default for MapperConfig {
    fn default() -> Self {
        MapperConfig {
            root: keys::DEFAULT_ROOT.to_owned(),
            instance: None,
            scenario: None,
            explore: Vec::new(),
            publish_period_s: 1.0,
            seed: 0,
            explorer: ExplorerParams::default(),
            map: MapParams::default(),
            news: NewsParams::default(),
            belief: BeliefParams::default(),
            zenoh: None,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum MapperServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Scenario(#[from] roam_world::scenario::ScenarioError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error(transparent)]
    World(#[from] WorldMismatch),
}

/// What observations and missions change, on one world's grid.
struct Mapping {
    /// The world the layers are of, sent with their updates.
    world: roam_proto::map::WorldId,
    /// Its grid.
    meta: GridMeta,
    /// Its static occupancy: the map now's prior for cells never seen.
    static_map: Grid<i8>,
    map: ChangeMap,
    /// The robots' reservations (their current missions).
    news: NewsMap,
    /// Each robot's last observed position, where its mission's path starts; kept for
    /// the first [`MAX_RESERVING_ROBOTS`] robots heard (a mission of any other starts at
    /// its first waypoint).
    positions: BTreeMap<String, [f64; 2]>,
    explorers: BTreeMap<String, Explorer>,
    /// The exploration goal last published per robot: a goal is published when it changes.
    published_goals: BTreeMap<String, ExplorationGoal>,
    observations: u64,
    map_changes: u64,
    features: (f64, f64),
    /// Mapper time ([`Epochs`]) of the newest observation.
    now_s: f64,
    /// Something was observed since the layers were last sent.
    dirty: bool,
    layers_sent: u64,
    /// Observation times against the sim clock; resets as epochs.
    epochs: Epochs,
}

/// What the mapper's subscribers, publisher and queryable share: the session and the
/// mapping under its lock.
struct MapperShared {
    root: String,
    session: zenoh::Session,
    mapping: Mutex<Mapping>,
    /// What a world's mapping is made of, for the world the map server moves to.
    spec: MappingSpec,
    /// Refused observations, logged a few per key and window.
    warnings: WarnLimiter,
    belief: BeliefParams,
    /// How far a robot sees along its mission's path, metres, and how fast it drives it.
    reserve_radius_m: f64,
    reserve_s_per_m: f64,
}

/// What a world's mapping is made of besides its grid.
struct MappingSpec {
    map: MapParams,
    news: NewsParams,
    explorer: ExplorerParams,
    seed: u64,
    explore: BTreeSet<String>,
}

impl MappingSpec {
    /// A fresh mapping of `world`, whose static occupancy is `static_map`.
    fn build(
        &self,
        world: roam_proto::map::WorldId,
        static_map: Grid<i8>,
    ) -> Result<Mapping, MapperServiceError> {
        let meta = static_map.meta;
        let config = |e: crate::error::MapperError| MapperServiceError::Config(e.to_string());
        let explorers = self
            .explore
            .iter()
            .map(|robot| {
                // Seeded by the robot's name, not its place in the list: a robot explores
                // the same way whichever other robots are explored beside it.
                let seed = crate::seed::labelled(self.seed, &format!("explore/{robot}"));
                Explorer::new(self.explorer, Mode::Curious, seed)
                    .map(|e| (robot.clone(), e))
                    .map_err(config)
            })
            .collect::<Result<_, _>>()?;
        Ok(Mapping {
            world,
            meta,
            static_map,
            map: ChangeMap::new(meta, self.map).map_err(config)?,
            news: NewsMap::new(meta, self.news.prior).map_err(config)?,
            positions: BTreeMap::new(),
            explorers,
            published_goals: BTreeMap::new(),
            observations: 0,
            map_changes: 0,
            features: (0.0, 0.0),
            now_s: 0.0,
            // Sent at once: the layers exist at the map's size before the first
            // observation, so a planner on the change coupling has one to plan on.
            dirty: true,
            layers_sent: 0,
            epochs: Epochs::default(),
        })
    }
}

impl MapperShared {
    fn mapping(&self) -> MutexGuard<'_, Mapping> {
        roam_runtime::lock(&self.mapping)
    }

    /// Commands, goals and statuses are state a robot must not miss: delivered.
    fn put<T: Message>(&self, key: &str, message: &T) {
        roam_runtime::publish_wait(&self.session, key, message, Delivery::Reliable);
    }
}

/// Why an observation cannot be merged (logged; a subscriber has no one to answer).
fn check_observation(meta: &GridMeta, o: &LocalObservation) -> Result<(), String> {
    if (o.meta.resolution - meta.resolution).abs() > 1e-9 * meta.resolution {
        return Err(format!(
            "its resolution {} m differs from the map's {} m",
            roam_proto::number(o.meta.resolution),
            meta.resolution
        ));
    }
    let (x1, y1) = (
        u64::from(o.x0) + u64::from(o.meta.width),
        u64::from(o.y0) + u64::from(o.meta.height),
    );
    if x1 > u64::from(meta.width) || y1 > u64::from(meta.height) {
        return Err(format!(
            "its window ends at cell ({x1}, {y1}), outside the {} x {} map",
            meta.width, meta.height
        ));
    }
    match &o.cells {
        Cells::I8(c) if c.len() as u64 == u64::from(o.meta.width) * u64::from(o.meta.height) => {
            Ok(())
        }
        Cells::I8(c) => Err(format!(
            "it has {} cells for a {} x {} window",
            c.len(),
            o.meta.width,
            o.meta.height
        )),
        _ => Err("its cells are not i8 occupancy values".to_owned()),
    }
}

fn cell_centre(meta: &GridMeta, (x, y): (u32, u32)) -> [f64; 2] {
    [
        meta.origin.x + (f64::from(x) + 0.5) * meta.resolution,
        meta.origin.y + (f64::from(y) + 0.5) * meta.resolution,
    ]
}

fn on_observation(state: &MapperShared, key: &str, o: LocalObservation) {
    let robot = match routing::robot_for(&state.root, key, &o.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "ignoring an observation: {e}"),
    };
    let meta = state.mapping().meta;
    if let Err(e) = check_observation(&meta, &o) {
        return limited_warn!(state.warnings, robot, %robot, step = o.step, "ignoring an observation: {e}");
    }
    let Some(window) = ObservationWindow::from_wire(&o) else {
        return;
    };
    let out = {
        let mut guard = state.mapping();
        let m = &mut *guard;
        if m.meta != meta {
            // The map server moved to another world meanwhile.
            return;
        }
        let t = match m.epochs.observation_time(o.time_s) {
            Ok(t) => t,
            Err(e) => {
                return limited_warn!(state.warnings, robot, %robot, "ignoring an observation: {e}");
            }
        };
        let update = match m.map.observe(&window, t) {
            Ok(u) => u,
            Err(e) => {
                return limited_warn!(state.warnings, robot, %robot, "ignoring an observation: {e}");
            }
        };
        m.epochs.accepted(t);
        m.observations += 1;
        if m.positions.len() < MAX_RESERVING_ROBOTS || m.positions.contains_key(robot) {
            m.positions.insert(robot.to_owned(), o.at);
        }
        m.map_changes += update.map_changes(true) as u64;
        m.now_s = m.now_s.max(t);
        m.dirty = true;
        let features = m.map.features(t);
        m.features = (features.p, features.r);
        match (m.explorers.get_mut(robot), m.map.cell_of(o.at)) {
            (Some(explorer), Some(cell)) => {
                match explorer.on_update(&mut m.map, &update, cell, t) {
                    Ok(step) => {
                        let at = cell_centre(&m.meta, step.episode_goal);
                        let strategy = step.strategy.as_str().to_owned();
                        let episodes = explorer.episodes_ended();
                        let fresh = m.published_goals.get(robot).is_none_or(|last| {
                            last.goal != at
                                || last.strategy != strategy
                                || last.episodes != episodes
                        });
                        let goal = fresh.then(|| {
                            let goal = ExplorationGoal {
                                robot: robot.to_owned(),
                                step: o.step,
                                time_s: o.time_s,
                                goal: at,
                                strategy,
                                episodes,
                            };
                            m.published_goals.insert(robot.to_owned(), goal.clone());
                            goal
                        });
                        Some((step.u, goal))
                    }
                    Err(e) => {
                        limited_warn!(state.warnings, robot, %robot, "no exploration step: {e}");
                        None
                    }
                }
            }
            _ => None,
        }
    };
    if let Some((u, goal)) = out {
        state.put(
            &keys::robot_command(&state.root, robot),
            &RobotCommand {
                u,
                step: Some(o.step),
            },
        );
        if let Some(goal) = goal {
            state.put(&keys::robot_goal(&state.root, robot), &goal);
        }
    }
}

/// A robot's new mission replaces its reservation ([`crate::news`]); an empty one
/// releases it.
fn on_mission(state: &MapperShared, key: &str, mission: Mission) {
    let robot = match routing::robot_for(&state.root, key, &mission.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "ignoring a mission: {e}"),
    };
    if mission.waypoints.is_empty() {
        let mut m = state.mapping();
        if m.news.release(robot) {
            m.dirty = true;
        }
        return;
    }
    // The path's cells are found outside the lock: a long path on a large map takes a
    // while, and observations keep merging meanwhile.
    let (start_s, position, meta) = {
        let m = state.mapping();
        (m.now_s, m.positions.get(robot).copied(), m.meta)
    };
    let path: Vec<[f64; 2]> = position
        .into_iter()
        .chain(mission.waypoints.iter().copied())
        .collect();
    let reserved = cells_along(
        &meta,
        &path,
        start_s,
        state.reserve_s_per_m,
        state.reserve_radius_m,
        MAX_RESERVED_CELLS,
    )
    .and_then(|cells| {
        let mut m = state.mapping();
        if m.meta != meta {
            return Ok(0);
        }
        let count = m.news.reserve(robot, cells)?;
        m.dirty = true;
        Ok(count)
    });
    if let Err(e) = reserved {
        limited_warn!(state.warnings, robot, %robot, "no reservation for a mission: {e}");
    }
}

fn status(state: &MapperShared) -> MapperStatus {
    let m = state.mapping();
    MapperStatus {
        observations: m.observations,
        map_changes: m.map_changes,
        p: m.features.0,
        r: m.features.1,
        layers_sent: m.layers_sent,
        explorers: m
            .explorers
            .iter()
            .map(|(robot, e)| {
                let published = m.published_goals.get(robot);
                ExplorerStatus {
                    robot: robot.clone(),
                    strategy: published.map(|g| g.strategy.clone()),
                    goal: published.map(|g| g.goal),
                    episodes: e.episodes_ended(),
                }
            })
            .collect(),
        reservations: m
            .news
            .reserving_robots()
            .map(|robot| ReservationStatus {
                robot: robot.to_owned(),
                cells: m.news.reserved_cells(robot) as u64,
            })
            .collect(),
    }
}

async fn answer_status(state: Arc<MapperShared>, query: Query) {
    let result: Result<MapperStatus, ErrorReply> = Ok(status(&state));
    reply::send_result(&query, result).await;
}

/// The layers to send, with the world and grid they are of.
struct LayersToSend {
    world: roam_proto::map::WorldId,
    meta: GridMeta,
    layers: Vec<(&'static str, Cells)>,
}

/// The layers at the newest observation's time, if anything was observed (or a mission
/// heard) since they were last sent.
fn layers_to_send(state: &MapperShared) -> Option<LayersToSend> {
    let mut m = state.mapping();
    if !m.dirty {
        return None;
    }
    m.dirty = false;
    let now = m.now_s;
    let probability = m.map.probability_layer(now).cells;
    let scores = crate::change_map::scores(&probability);
    let mut layers = vec![
        (
            CHANGE_RATE_LAYER,
            Cells::F32(f32_cells(m.map.rate_layer().cells)),
        ),
        (CHANGE_PROBABILITY_LAYER, Cells::F32(f32_cells(probability))),
        (CHANGE_INFORMATION_LAYER, Cells::U8(scores)),
        (
            RECENCY_LAYER,
            Cells::F32(f32_cells(m.map.recency_layer(now).cells)),
        ),
    ];
    // Both are on the change map's grid by construction; an error would be a bug, logged
    // and that layer left out.
    match m.news.news_scores(&m.map, now, None) {
        Ok(news) => layers.push((NEWS_LAYER, Cells::U8(news.cells))),
        Err(e) => tracing::error!("no news layer: {e}"),
    }
    match occupied_now(&m.map, now, &state.belief, Some(&m.static_map)) {
        Ok(belief) => layers.push((OCCUPIED_NOW_LAYER, Cells::I8(belief.cells))),
        Err(e) => tracing::error!("no occupied_now layer: {e}"),
    }
    Some(LayersToSend {
        world: m.world.clone(),
        meta: m.meta,
        layers,
    })
}

/// Moves the mapping to the world the map server holds when it is another than the
/// mapping's (the map server took a map of another grid: `--ros2-map`, `map/load`):
/// what was learnt of the old world's cells means nothing on the new one, so the
/// mapping starts afresh on the new occupancy, and its layers go out on the new grid
/// for the new world. The map server has forgotten the old grid's layers by then.
async fn follow_world(state: &MapperShared, list: &LayerList, requester: &Requester) {
    let Some(theirs) = &list.world else {
        return;
    };
    if state.mapping().world.hash == theirs.hash {
        return;
    }
    let key = keys::map_layer(&state.root, OCCUPANCY_LAYER);
    let occupancy = match requester.request::<Layer, Layer>(&key, None).await {
        Ok(layer) => layer,
        Err(e) => return tracing::debug!("the new world's occupancy is not here yet: {e}"),
    };
    let Cells::I8(cells) = occupancy.cells else {
        return tracing::warn!("the map server's occupancy is not i8 cells; the mapping stays");
    };
    if cells.len() as u64 != occupancy.meta.cell_count() {
        return tracing::warn!("the map server's occupancy has the wrong cell count");
    }
    let static_map = Grid {
        meta: occupancy.meta,
        cells,
    };
    match state.spec.build(theirs.clone(), static_map) {
        Ok(fresh) => {
            let mut m = state.mapping();
            tracing::info!(
                world = %theirs,
                was = %m.world,
                "the map server holds another world: mapping it afresh on its {}x{} grid",
                occupancy.meta.width,
                occupancy.meta.height
            );
            let (epochs, now_s) = (m.epochs.clone(), m.now_s);
            *m = Mapping {
                epochs,
                now_s,
                ..fresh
            };
        }
        Err(e) => tracing::error!("cannot map the map server's new world: {e}"),
    }
}

/// Layers travel as f32 cells: the map server's float layer type, half the bytes.
fn f32_cells(cells: Vec<f64>) -> Vec<f32> {
    cells.into_iter().map(|v| v as f32).collect()
}

/// Sends the layers to the map server at most once per period.
async fn publish_layers(state: Arc<MapperShared>, period: Duration, cancel: CancellationToken) {
    let requester = Requester::new(state.session.clone(), Duration::from_secs(5));
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(period) => {}
        }
        let list: LayerList = match requester
            .request::<LayerList, LayerList>(&keys::map_index(&state.root), None)
            .await
        {
            Ok(l) => l,
            Err(e) => {
                tracing::debug!("no map server to send the layers to: {e}");
                continue;
            }
        };
        follow_world(&state, &list, &requester).await;
        let Some(LayersToSend {
            world,
            meta,
            layers,
        }) = layers_to_send(&state)
        else {
            continue;
        };
        let meta = GridMeta {
            origin: Origin {
                yaw: 0.0,
                ..meta.origin
            },
            ..meta
        };
        let mut all_sent = true;
        for (name, cells) in layers {
            let base_version = list
                .layers
                .iter()
                .find(|l| l.name == name)
                .map_or(0, |l| l.version);
            let update = LayerUpdate {
                base_version,
                change: LayerChange::Replace { meta, cells },
                world: Some(world.clone()),
            };
            let sent = requester
                .request::<LayerUpdate, UpdateAck>(
                    &keys::map_update(&state.root, name),
                    Some(&update),
                )
                .await;
            if let Err(e) = sent {
                all_sent = false;
                tracing::warn!(layer = name, "the map server refused the layer: {e}");
            }
        }
        if all_sent {
            state.mapping().layers_sent += 1;
        } else {
            state.mapping().dirty = true;
        }
    }
}

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
    let mut service = Service::start(
        SERVICE_NAME,
        &config.root,
        config.instance.as_deref(),
        zenoh_config,
        cancel,
    )
    .await?;
    let world_guard = world_check::guard(&service, world);
    let state = Arc::new(MapperShared {
        root: config.root.clone(),
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
            &keys::sim_clock(&config.root),
            MAX_CLOCK_BYTES,
            state.clone(),
            |state: &Arc<MapperShared>, _key: &str, clock: SimClock| {
                state.mapping().epochs.on_clock(clock.time_s)
            },
        )
        .await?;
    service
        .subscribe_with(
            &keys::robot_observation_any(&config.root),
            MAX_OBSERVATION_BYTES,
            state.clone(),
            |state: &Arc<MapperShared>, key: &str, o: LocalObservation| {
                on_observation(state, key, o)
            },
        )
        .await?;
    service
        .subscribe_with(
            &keys::robot_mission_any(&config.root),
            MAX_MISSION_BYTES,
            state.clone(),
            |state: &Arc<MapperShared>, key: &str, mission: Mission| {
                on_mission(state, key, mission)
            },
        )
        .await?;
    let status_queryable = service
        .declare_queryable(&keys::mapper_status(&config.root))
        .await?;
    service.serve(status_queryable, state.clone(), |s, q| async move {
        answer_status(s, q).await
    });
    let (published, token) = (state.clone(), service.cancel_token());
    let period = Duration::from_secs_f64(config.publish_period_s);
    service.spawn(async move { publish_layers(published, period, token).await });
    service.announce().await?;
    service.run_until_stopped().await?;
    world_guard.outcome()?;
    Ok(())
}
