//! The Zenoh side: follows roam's keys and logs what it sees on the Foxglove topics.
//!
//! Two loops share the outputs. The *world* loop follows the map server's layers (each
//! publication; each delta, applied to the layer shown when it is the delta's base
//! version, else the whole layer is fetched; plus a look at `<root>/map/layers` at start
//! and every [`REFRESH_PERIOD`], fetching every layer whose version it has not shown: a
//! view started after the map server, or a map server restarted, is caught up) and asks the sim
//! for its anchors and robots on the same period. The *robots* loop follows the true
//! positions, the estimates and the missions.
//!
//! Nothing from the wire is trusted (see `wire`): every payload is checked against its
//! kind's cap before it is decoded, robot and layer names must be key segments and match
//! the key they came on, missions are held to the controller's limits, and every queue
//! and table is bounded: the subscribers are ring buffers (the oldest sample goes when
//! one is full), at most [`MAX_LAYERS`] layers of [`MAX_LAYER_BYTES_SHOWN`] together are
//! shown, and per-robot state (missions, driven paths) is kept for at most [`MAX_ROBOTS`]
//! robots each (see `roster`: the sim's own robots are never evicted by strangers).

use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

use foxglove::messages::{Grid, SceneUpdate, Timestamp};
use roam_map_server::store::DEFAULT_LIMITS;
use roam_proto::controller::{Mission, MAX_WAYPOINTS};
use roam_proto::layer_delta::{LayerDelta, MAX_DELTA_BYTES};
use roam_proto::localization::PositionEstimate;
use roam_proto::map::{Layer, LayerList};
use roam_proto::sim::{GroundTruth, NamedPoint, SimControl, SimStatus};
use roam_proto::{keys, Message};
use roam_runtime::{FleetStreams, LatestSamples};
use tokio::sync::watch;
use tokio::time::{Instant, MissedTickBehavior};
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;
use zenoh::Session;

use crate::convert::{self, DrivenPath};
use crate::output::{Outputs, Topic};
use crate::roster::{Roster, Touched};
use crate::wire::{self, clipped, decode_bounded, shown};

/// The most map layers shown (the map server's own default limit, `max_layers`).
pub const MAX_LAYERS: usize = DEFAULT_LIMITS.max_layers as usize;
/// The most cells of one layer shown (the map server's `max_layer_cells`).
pub const MAX_LAYER_CELLS: u64 = DEFAULT_LIMITS.max_layer_cells;
/// The most bytes of grid cells kept for the layers shown, together (their latched
/// messages): nine full-size layers of f32 fit, 64 of them do not.
pub const MAX_LAYER_BYTES_SHOWN: usize = 1 << 30;
/// The largest layer kept as well as shown, bytes of cells, for deltas to apply to (a
/// 1.7-million-cell warehouse map's f32 layers are 6.8 MB); a delta of a larger layer
/// fetches it whole, so the largest layers are not held twice.
pub const MAX_LAYER_BYTES_KEPT: usize = 16 << 20;
pub use crate::roster::MAX_ROBOTS;
/// The most points kept per driven path, and the least distance between two of them.
pub const DRIVEN_POINTS: usize = 4096;
pub const DRIVEN_STEP_M: f64 = 0.05;
/// The driven paths are logged at most this often.
pub const DRIVEN_PERIOD: Duration = Duration::from_millis(250);
/// How often the world loop looks at the layer index and the sim's status.
pub const REFRESH_PERIOD: Duration = Duration::from_secs(5);
/// How long one of its queries may take.
pub const QUERY_TIMEOUT: Duration = Duration::from_secs(2);

/// The fixed topics.
pub const TRUTH_TOPIC: &str = "/robots/truth";
pub const ESTIMATE_TOPIC: &str = "/robots/estimate";
pub const MISSION_TOPIC: &str = "/robots/mission";
pub const DRIVEN_TOPIC: &str = "/robots/driven";
pub const ANCHORS_TOPIC: &str = "/anchors";

type Ring = LatestSamples;

/// The names of the robots in the sim's last status.
type SimRobots = Arc<BTreeSet<String>>;

/// Decodes a sample's payload of at most `max` bytes, or counts it dropped.
fn decode_sample<T: Message>(out: &Outputs, sample: &Sample, max: usize) -> Option<T> {
    match decode_bounded::<T>(sample.payload(), max) {
        Ok(message) => Some(message),
        Err(e) => {
            out.counters.unread(sample.key_expr().as_str(), &e);
            None
        }
    }
}

/// Checks that `robot` is a valid robot name and the one `key` (`<root>/robot/<id>/…`)
/// is for: a message about robot A put on robot B's key is not believed.
fn check_robot(root: &str, key: &str, robot: &str) -> Result<(), String> {
    if keys::check_name("robot", robot).is_err() {
        return Err(format!(
            "the robot name \"{}\" is not a key segment (1 to {} of a-z, A-Z, 0-9, '_', '-')",
            shown(robot),
            keys::MAX_SEGMENT_LEN
        ));
    }
    let named = key
        .strip_prefix(root)
        .and_then(|k| k.strip_prefix("/robot/"))
        .and_then(|k| k.split('/').next());
    if named != Some(robot) {
        return Err(format!(
            "a message about robot \"{}\" on another robot's key",
            shown(robot)
        ));
    }
    Ok(())
}

/// The fixed robot topics.
struct RobotTopics {
    truth: Topic,
    estimate: Topic,
    mission: Topic,
    driven: Topic,
}

impl RobotTopics {
    fn new(out: &Outputs) -> Self {
        RobotTopics {
            truth: out.topic::<SceneUpdate>(TRUTH_TOPIC, false),
            estimate: out.topic::<SceneUpdate>(ESTIMATE_TOPIC, false),
            mission: out.topic::<SceneUpdate>(MISSION_TOPIC, true),
            driven: out.topic::<SceneUpdate>(DRIVEN_TOPIC, true),
        }
    }
}

/// Runs both loops until `cancel`.
pub(crate) async fn follow(
    session: Session,
    root: String,
    subscriptions: FleetStreams,
    out: Arc<Outputs>,
    cancel: CancellationToken,
) {
    let FleetStreams {
        layers,
        deltas,
        truth,
        estimate,
        mission,
    } = subscriptions;
    let robots = RobotTopics::new(&out);
    let anchors = out.topic::<SceneUpdate>(ANCHORS_TOPIC, true);
    let (sim_tx, sim_rx) = watch::channel(SimRobots::default());
    let world = World {
        out: out.clone(),
        root: root.clone(),
        session,
        layers: BTreeMap::new(),
        layer_bytes: 0,
        anchors_topic: anchors,
        truth_topic: robots.truth.clone(),
        anchors: None,
        robots: None,
        sim: sim_tx,
    };
    let robots = Robots {
        out,
        root,
        topics: robots,
        missions: Roster::new(MAX_ROBOTS),
        driven: Roster::new(MAX_ROBOTS),
        driven_dirty: false,
        sim: sim_rx,
    };
    tokio::join!(
        world.run(layers, deltas, cancel.clone()),
        robots.run(truth, estimate, mission, cancel),
    );
}

/// A layer shown: its topic, its version, the layer itself when it is small enough to
/// keep for deltas ([`MAX_LAYER_BYTES_KEPT`]) and the bytes its cells take.
struct Shown {
    topic: Topic,
    version: u64,
    layer: Option<Layer>,
    bytes: usize,
}

/// The map layers, the anchors and the sim's robot list.
struct World {
    out: Arc<Outputs>,
    root: String,
    session: Session,
    layers: BTreeMap<String, Shown>,
    /// The bytes of cells of every layer shown.
    layer_bytes: usize,
    anchors_topic: Topic,
    truth_topic: Topic,
    anchors: Option<Vec<NamedPoint>>,
    robots: Option<Vec<NamedPoint>>,
    sim: watch::Sender<SimRobots>,
}

impl World {
    async fn run(mut self, layers: Ring, deltas: Ring, cancel: CancellationToken) {
        let mut refresh = tokio::time::interval(REFRESH_PERIOD);
        refresh.set_missed_tick_behavior(MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = layers.recv_async() => match sample {
                    Ok(sample) => self.on_layer(&sample),
                    Err(_) => break,
                },
                sample = deltas.recv_async() => match sample {
                    Ok(sample) => {
                        tokio::select! {
                            _ = cancel.cancelled() => break,
                            _ = self.on_delta(&sample) => {}
                        }
                    }
                    Err(_) => break,
                },
                _ = refresh.tick() => {
                    tokio::select! {
                        _ = cancel.cancelled() => break,
                        _ = self.refresh() => {}
                    }
                }
            }
        }
    }

    fn on_layer(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let Some(layer) = decode_sample::<Layer>(&self.out, sample, wire::MAX_LAYER_BYTES) else {
            return;
        };
        if key != keys::map_layer(&self.root, &layer.name) {
            self.out.counters.dropped(
                key,
                &format!("a layer named \"{}\" on another key", shown(&layer.name)),
            );
            return;
        }
        self.show_layer(layer, true);
    }

    /// A delta of a layer shown: applied to it when it is the delta's base version;
    /// ignored when the view already shows the delta's version or a later one (a delta
    /// that arrived late; a map server restarted with lower versions is caught up by the
    /// refresh); otherwise (the view missed a delta, shows nothing of the layer, or did
    /// not keep a layer that large) the whole layer is fetched.
    async fn on_delta(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let Some(delta) = decode_sample::<LayerDelta>(&self.out, sample, MAX_DELTA_BYTES) else {
            return;
        };
        if key != keys::map_delta(&self.root, &delta.name) {
            return self.out.counters.dropped(
                key,
                &format!("a delta of \"{}\" on another key", shown(&delta.name)),
            );
        }
        let Some(held) = self.layers.get(&delta.name) else {
            return self.fetch(&delta.name).await;
        };
        if held.version >= delta.version {
            return;
        }
        let Some(mut layer) = held.layer.clone() else {
            return self.fetch(&delta.name).await;
        };
        match delta.apply(&mut layer) {
            Ok(()) => self.show_layer(layer, true),
            Err(e) => {
                tracing::debug!(layer = %delta.name, "roam view: {e}");
                self.fetch(&delta.name).await;
            }
        }
    }

    /// Fetches layer `name` whole and shows it when its version is not the one shown.
    async fn fetch(&mut self, name: &str) {
        // A name that is not a key segment would make a key of its own (a wildcard, say).
        let index = keys::map_index(&self.root);
        if keys::check_name("layer", name).is_err() {
            let reason = format!("a layer named \"{}\"", shown(name));
            return self.out.counters.dropped(&index, &reason);
        }
        let key = keys::map_layer(&self.root, name);
        let fetched = wire::query::<Layer, Layer>(
            &self.session,
            &key,
            None,
            wire::MAX_LAYER_BYTES,
            QUERY_TIMEOUT,
        )
        .await;
        match fetched {
            Ok(layer) if layer.name == name => self.show_layer(layer, false),
            Ok(layer) => self
                .out
                .counters
                .dropped(&key, &format!("a layer named \"{}\"", shown(&layer.name))),
            Err(e) => self.out.counters.unread(&key, &e),
        }
    }

    /// Shows a layer unless this version is already shown. A published layer is always
    /// news; a fetched one only when its version differs from the one shown.
    fn show_layer(&mut self, layer: Layer, published: bool) {
        let key = keys::map_layer(&self.root, &layer.name);
        let shown_before = self.layers.get(&layer.name);
        if let Some(before) = shown_before {
            if before.version == layer.version && !published {
                return;
            }
        }
        let refusal = if keys::check_name("layer", &layer.name).is_err() {
            Some(format!(
                "the layer name \"{}\" is not a key segment",
                shown(&layer.name)
            ))
        } else if shown_before.is_none() && self.layers.len() >= MAX_LAYERS {
            Some(format!(
                "more than {MAX_LAYERS} layers; this one is not shown"
            ))
        } else if layer.meta.cell_count() > MAX_LAYER_CELLS {
            Some(format!(
                "{} cells; a layer is shown up to {MAX_LAYER_CELLS} (max_layer_cells)",
                layer.meta.cell_count()
            ))
        } else {
            None
        };
        let bytes = layer.cells.len() * layer.cells.dtype().size();
        let others = self.layer_bytes - shown_before.map_or(0, |s| s.bytes);
        let refusal = refusal.or_else(|| {
            (others + bytes > MAX_LAYER_BYTES_SHOWN).then(|| {
                format!("the layers shown would hold more than {MAX_LAYER_BYTES_SHOWN} bytes")
            })
        });
        if let Some(reason) = refusal {
            return self.out.counters.dropped(&key, &reason);
        }
        let grid = match convert::grid(&layer, Timestamp::now()) {
            Ok(grid) => grid,
            Err(e) => return self.out.counters.dropped(&key, &e),
        };
        let out = &self.out;
        tracing::debug!(layer = %layer.name, version = layer.version, "roam view: layer shown");
        let topic = match self.layers.remove(&layer.name) {
            Some(before) => before.topic,
            None => out.topic::<Grid>(&convert::layer_topic(&layer.name), true),
        };
        out.log(&topic, &grid);
        self.layers.insert(
            layer.name.clone(),
            Shown {
                topic,
                version: layer.version,
                layer: (bytes <= MAX_LAYER_BYTES_KEPT).then_some(layer),
                bytes,
            },
        );
        self.layer_bytes = others + bytes;
    }

    /// Fetches every layer not shown at its current version, and the sim's status.
    async fn refresh(&mut self) {
        let index = keys::map_index(&self.root);
        match wire::query::<Layer, LayerList>(
            &self.session,
            &index,
            None,
            wire::MAX_LAYER_LIST_BYTES,
            QUERY_TIMEOUT,
        )
        .await
        {
            Ok(list) => {
                for info in list.layers.iter().take(MAX_LAYERS) {
                    // A name that is not a key segment would make a key of its own
                    // (a wildcard, say) for the query below.
                    if keys::check_name("layer", &info.name).is_err() {
                        let reason = format!("a layer named \"{}\"", shown(&info.name));
                        self.out.counters.dropped(&index, &reason);
                        continue;
                    }
                    let version = self.layers.get(&info.name).map(|s| s.version);
                    if version == Some(info.version) {
                        continue;
                    }
                    self.fetch(&info.name).await;
                }
            }
            Err(e) => tracing::debug!("roam view: no layer index yet: {}", clipped(&e.to_string())),
        }
        match wire::query::<SimControl, SimStatus>(
            &self.session,
            &keys::sim_control(&self.root),
            Some(&SimControl::Status),
            wire::MAX_SIM_STATUS_BYTES,
            QUERY_TIMEOUT,
        )
        .await
        {
            Ok(status) => self.show_status(status),
            Err(e) => tracing::debug!("roam view: no sim status yet: {}", clipped(&e.to_string())),
        }
    }

    fn show_status(&mut self, status: SimStatus) {
        let now = Timestamp::now();
        if self.robots.as_ref() != Some(&status.robots) {
            let key = keys::sim_control(&self.root);
            let mut named = BTreeSet::new();
            for robot in &status.robots {
                if keys::check_name("robot", &robot.name).is_err() {
                    let reason = format!("the sim names a robot \"{}\"", shown(&robot.name));
                    self.out.counters.dropped(&key, &reason);
                } else if named.len() < MAX_ROBOTS {
                    named.insert(robot.name.clone());
                }
            }
            self.out
                .counters
                .sim_robots
                .store(named.len(), Ordering::Relaxed);
            // The robots where the sim has them: seen even when the sim is paused (it then
            // publishes no true positions).
            for robot in status.robots.iter().filter(|r| named.contains(&r.name)) {
                let truth = GroundTruth {
                    robot: robot.name.clone(),
                    step: status.step,
                    time_s: status.time_s,
                    at: robot.at,
                };
                self.out
                    .log(&self.truth_topic, &convert::truth(&truth, now));
            }
            self.sim.send_replace(Arc::new(named));
            self.robots = Some(status.robots);
        }
        if self.anchors.as_ref() != Some(&status.anchors) {
            self.out
                .log(&self.anchors_topic, &convert::anchors(&status.anchors, now));
            self.anchors = Some(status.anchors);
        }
    }
}

/// One robot's driven path and whether it changed since it was last logged.
struct LoggedPath {
    path: DrivenPath,
    dirty: bool,
}

/// True positions, estimates, missions and driven paths.
struct Robots {
    out: Arc<Outputs>,
    root: String,
    topics: RobotTopics,
    /// The robots whose missions are drawn (the drawings are kept in the latch).
    missions: Roster<()>,
    driven: Roster<LoggedPath>,
    driven_dirty: bool,
    sim: watch::Receiver<SimRobots>,
}

impl Robots {
    async fn run(mut self, truth: Ring, estimate: Ring, mission: Ring, cancel: CancellationToken) {
        let mut last_driven = Instant::now();
        let mut flush = tokio::time::interval(DRIVEN_PERIOD);
        flush.set_missed_tick_behavior(MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = mission.recv_async() => match sample {
                    Ok(sample) => self.on_mission(&sample),
                    Err(_) => break,
                },
                sample = truth.recv_async() => match sample {
                    Ok(sample) => self.on_truth(&sample),
                    Err(_) => break,
                },
                sample = estimate.recv_async() => match sample {
                    Ok(sample) => self.on_estimate(&sample),
                    Err(_) => break,
                },
                _ = flush.tick() => {}
            }
            if self.driven_dirty && last_driven.elapsed() >= DRIVEN_PERIOD {
                self.log_driven();
                last_driven = Instant::now();
            }
        }
        if self.driven_dirty {
            self.log_driven();
        }
    }

    /// Counts the robots with per-robot state, for [`crate::ViewStats`].
    fn count_robots(&self) {
        let missions = &self.missions;
        let only_driven = self
            .driven
            .names()
            .filter(|robot| !missions.contains(robot))
            .count();
        self.out
            .counters
            .robots
            .store(missions.len() + only_driven, Ordering::Relaxed);
    }

    /// Whether the message about `robot` on `key` is believed (else it is counted dropped).
    fn believed(&self, key: &str, robot: &str) -> bool {
        match check_robot(&self.root, key, robot) {
            Ok(()) => true,
            Err(reason) => {
                self.out.counters.dropped(key, &reason);
                false
            }
        }
    }

    fn on_truth(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let Some(t) = decode_sample::<GroundTruth>(&self.out, sample, wire::MAX_TRUTH_BYTES) else {
            return;
        };
        if !self.believed(key, &t.robot) {
            return;
        }
        self.out
            .log(&self.topics.truth, &convert::truth(&t, Timestamp::now()));
        let sim = self.sim.borrow().clone();
        let touched = self.driven.touch(
            &t.robot,
            |r| sim.contains(r),
            || LoggedPath {
                path: DrivenPath::new(DRIVEN_POINTS, DRIVEN_STEP_M),
                dirty: false,
            },
        );
        match touched {
            Touched::Refused => return self.out.counters.dropped(key, &full(&t.robot)),
            Touched::Evicted(gone) => {
                let update = convert::driven_deleted(&gone, Timestamp::now());
                self.out.log(&self.topics.driven, &update);
                self.out.forget_robot(&self.topics.driven, &gone);
            }
            Touched::Kept => {}
        }
        if let Some(driven) = self.driven.get_mut(&t.robot) {
            let moved = driven.path.push(t.at);
            driven.dirty |= moved;
            self.driven_dirty |= moved;
        }
        self.count_robots();
    }

    fn on_estimate(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let max = wire::MAX_ESTIMATE_BYTES;
        let Some(p) = decode_sample::<PositionEstimate>(&self.out, sample, max) else {
            return;
        };
        if self.believed(key, &p.robot) {
            let update = convert::estimate(&p, Timestamp::now());
            self.out.log(&self.topics.estimate, &update);
        }
    }

    fn on_mission(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let max = wire::MAX_MISSION_BYTES;
        let Some(m) = decode_sample::<Mission>(&self.out, sample, max) else {
            return;
        };
        if !self.believed(key, &m.robot) {
            return;
        }
        // Held to the controller's own checks: the view draws what a robot would drive.
        if m.waypoints.len() > MAX_WAYPOINTS {
            let reason = format!(
                "{} waypoints; a mission holds at most {MAX_WAYPOINTS}",
                m.waypoints.len()
            );
            return self.out.counters.dropped(key, &reason);
        }
        if m.waypoints
            .iter()
            .any(|w| !(w[0].is_finite() && w[1].is_finite()))
        {
            return self
                .out
                .counters
                .dropped(key, &"a waypoint is not a finite point");
        }
        let now = Timestamp::now();
        if m.waypoints.is_empty() {
            // Stopped: the drawing goes, and so does the robot's place in the roster.
            self.missions.remove(&m.robot);
            self.out.forget_robot(&self.topics.mission, &m.robot);
            self.out.log(
                &self.topics.mission,
                &convert::mission_deleted(&m.robot, now),
            );
            return self.count_robots();
        }
        let sim = self.sim.borrow().clone();
        match self.missions.touch(&m.robot, |r| sim.contains(r), || ()) {
            Touched::Refused => return self.out.counters.dropped(key, &full(&m.robot)),
            Touched::Evicted(gone) => {
                self.out.forget_robot(&self.topics.mission, &gone);
                self.out
                    .log(&self.topics.mission, &convert::mission_deleted(&gone, now));
            }
            Touched::Kept => {}
        }
        self.out
            .log_robot(&self.topics.mission, &m.robot, &convert::mission(&m, now));
        self.count_robots();
    }

    /// Logs the path of each robot that moved since the last time (each robot's is kept
    /// for clients that subscribe later).
    fn log_driven(&mut self) {
        let now = Timestamp::now();
        let (out, topic) = (&self.out, &self.topics.driven);
        for (robot, driven) in self.driven.iter_mut() {
            if driven.dirty {
                let update = convert::driven([(robot, &driven.path)].into_iter(), now);
                out.log_robot(topic, robot, &update);
                driven.dirty = false;
            }
        }
        self.driven_dirty = false;
    }
}

fn full(robot: &str) -> String {
    format!(
        "more than {MAX_ROBOTS} robots, all named by the sim; robot \"{}\" is not drawn",
        shown(robot)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_robot_must_be_a_key_segment_and_the_key_s_robot() {
        let root = "roam/site-1";
        assert_eq!(
            check_robot(root, "roam/site-1/robot/r1/mission", "r1"),
            Ok(())
        );
        let other = check_robot(root, "roam/site-1/robot/r2/mission", "r1");
        assert!(other.is_err_and(|e| e.contains("another robot's key")));
        let evil = "r1\n\u{1b}[2J";
        let refused = check_robot(root, "roam/site-1/robot/r1/mission", evil).expect_err("evil");
        assert!(
            !refused.contains('\n') && !refused.contains('\u{1b}'),
            "{refused}"
        );
        let long = "r".repeat(1 << 20);
        let refused = check_robot(root, "roam/site-1/robot/r/mission", &long).expect_err("long");
        assert!(refused.len() < 300, "{} bytes", refused.len());
        assert!(check_robot(root, "other/robot/r1/mission", "r1").is_err());
    }
}
