//! The Zenoh side: follows roam's keys and logs what it sees on the Foxglove topics.
//!
//! Two loops share the outputs. The *world* loop follows the map server's layers (each
//! publication, plus a look at `<root>/map/layers` at start and every
//! [`REFRESH_PERIOD`], fetching every layer whose version it has not shown: a view
//! started after the map server, or a map server restarted, is caught up) and asks the sim
//! for its anchors and robots on the same period. The *robots* loop follows the true
//! positions, the estimates and the missions. Every queue is bounded: the subscribers are
//! ring buffers (the oldest sample goes when one is full), and the per-robot state holds
//! at most [`MAX_ROBOTS`] robots and [`DRIVEN_POINTS`] points per driven path.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Duration;

use foxglove::messages::{Grid, SceneUpdate, Timestamp};
use roam_proto::controller::Mission;
use roam_proto::localization::PositionEstimate;
use roam_proto::map::{Layer, LayerList};
use roam_proto::sim::{GroundTruth, NamedPoint, SimControl, SimStatus};
use roam_proto::{decode, keys, Message};
use roam_runtime::Requester;
use tokio::time::{Instant, MissedTickBehavior};
use tokio_util::sync::CancellationToken;
use zenoh::handlers::{RingChannel, RingChannelHandler};
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;
use zenoh::Session;

use crate::convert::{self, DrivenPath};
use crate::output::{Outputs, Topic};
use crate::ViewError;

/// The most map layers shown (the map server's own default limit).
pub const MAX_LAYERS: usize = 64;
/// The most robots whose missions and driven paths are kept.
pub const MAX_ROBOTS: usize = 256;
/// Samples a robot subscription holds before the oldest go.
pub const ROBOT_QUEUE: usize = 256;
/// Layers the layer subscription holds before the oldest go (a dropped one is fetched
/// again at the next refresh, whose version check sees it missing).
pub const LAYER_QUEUE: usize = 8;
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

type Ring = Subscriber<RingChannelHandler<Sample>>;

/// The subscriptions, declared before `run` returns so nothing published after is missed.
pub(crate) struct Subscriptions {
    layers: Ring,
    truth: Ring,
    estimate: Ring,
    mission: Ring,
}

impl Subscriptions {
    pub(crate) async fn declare(session: &Session, root: &str) -> Result<Self, ViewError> {
        let ring = |key: String, capacity: usize| {
            let session = session.clone();
            async move {
                session
                    .declare_subscriber(key.clone())
                    .with(RingChannel::new(capacity))
                    .await
                    .map_err(|e| ViewError::Zenoh(format!("subscribing to '{key}': {e}")))
            }
        };
        Ok(Subscriptions {
            layers: ring(keys::map_layer_any(root), LAYER_QUEUE).await?,
            // `robot_truth` with the robot `*`: every robot's true position.
            truth: ring(keys::robot_truth(root, "*"), ROBOT_QUEUE).await?,
            estimate: ring(keys::robot_estimate_any(root), ROBOT_QUEUE).await?,
            mission: ring(keys::robot_mission_any(root), ROBOT_QUEUE).await?,
        })
    }
}

fn decode_sample<T: Message>(out: &Outputs, sample: &Sample) -> Option<T> {
    match decode::<T>(&sample.payload().to_bytes()) {
        Ok(message) => Some(message),
        Err(e) => {
            out.counters.dropped(sample.key_expr().as_str(), &e);
            None
        }
    }
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
    subscriptions: Subscriptions,
    out: Arc<Outputs>,
    cancel: CancellationToken,
) {
    let Subscriptions {
        layers,
        truth,
        estimate,
        mission,
    } = subscriptions;
    let robots = RobotTopics::new(&out);
    let anchors = out.topic::<SceneUpdate>(ANCHORS_TOPIC, true);
    let requester = Requester::new(session, QUERY_TIMEOUT);
    let world = World {
        out: out.clone(),
        root,
        requester,
        layers: BTreeMap::new(),
        anchors_topic: anchors,
        truth_topic: robots.truth.clone(),
        anchors: None,
        robots: None,
    };
    let robots = Robots {
        out,
        topics: robots,
        missions: BTreeMap::new(),
        driven: BTreeMap::new(),
        driven_dirty: false,
        full_warned: false,
    };
    tokio::join!(
        world.run(layers, cancel.clone()),
        robots.run(truth, estimate, mission, cancel),
    );
}

/// The map layers, the anchors and the sim's robot list.
struct World {
    out: Arc<Outputs>,
    root: String,
    requester: Requester,
    /// Per layer: its topic and the version last shown.
    layers: BTreeMap<String, (Topic, u64)>,
    anchors_topic: Topic,
    truth_topic: Topic,
    anchors: Option<Vec<NamedPoint>>,
    robots: Option<Vec<NamedPoint>>,
}

impl World {
    async fn run(mut self, layers: Ring, cancel: CancellationToken) {
        let mut refresh = tokio::time::interval(REFRESH_PERIOD);
        refresh.set_missed_tick_behavior(MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = layers.recv_async() => match sample {
                    Ok(sample) => {
                        if let Some(layer) = decode_sample::<Layer>(&self.out, &sample) {
                            self.show_layer(&layer, true);
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

    /// Shows a layer unless this version is already shown. A published layer is always
    /// news; a fetched one only when its version differs from the one shown.
    fn show_layer(&mut self, layer: &Layer, published: bool) {
        if let Some((_, shown)) = self.layers.get(&layer.name) {
            if *shown == layer.version && !published {
                return;
            }
        } else if self.layers.len() >= MAX_LAYERS {
            self.out.counters.dropped(
                &keys::map_layer(&self.root, &layer.name),
                &format!("more than {MAX_LAYERS} layers; this one is not shown"),
            );
            return;
        }
        let grid = match convert::grid(layer, Timestamp::now()) {
            Ok(grid) => grid,
            Err(e) => {
                self.out
                    .counters
                    .dropped(&keys::map_layer(&self.root, &layer.name), &e);
                return;
            }
        };
        let out = &self.out;
        let (topic, shown) = self.layers.entry(layer.name.clone()).or_insert_with(|| {
            (
                out.topic::<Grid>(&convert::layer_topic(&layer.name), true),
                0,
            )
        });
        out.log(topic, &grid);
        *shown = layer.version;
        tracing::debug!(layer = %layer.name, version = layer.version, "roam view: layer shown");
    }

    /// Fetches every layer not shown at its current version, and the sim's status.
    async fn refresh(&mut self) {
        match self
            .requester
            .request::<Layer, LayerList>(&keys::map_index(&self.root), None)
            .await
        {
            Ok(list) => {
                for info in list.layers {
                    let shown = self.layers.get(&info.name).map(|(_, v)| *v);
                    if shown == Some(info.version) {
                        continue;
                    }
                    let key = keys::map_layer(&self.root, &info.name);
                    match self.requester.request::<Layer, Layer>(&key, None).await {
                        Ok(layer) => self.show_layer(&layer, false),
                        Err(e) => tracing::debug!("roam view: {e}"),
                    }
                }
            }
            Err(e) => tracing::debug!("roam view: no layer index yet: {e}"),
        }
        match self
            .requester
            .request::<SimControl, SimStatus>(
                &keys::sim_control(&self.root),
                Some(&SimControl::Status),
            )
            .await
        {
            Ok(status) => self.show_status(status),
            Err(e) => tracing::debug!("roam view: no sim status yet: {e}"),
        }
    }

    fn show_status(&mut self, status: SimStatus) {
        let now = Timestamp::now();
        if self.anchors.as_ref() != Some(&status.anchors) {
            self.out
                .log(&self.anchors_topic, &convert::anchors(&status.anchors, now));
            self.anchors = Some(status.anchors);
        }
        // The robots where the sim has them: seen even when the sim is paused (it then
        // publishes no true positions).
        if self.robots.as_ref() != Some(&status.robots) {
            for robot in status.robots.iter().take(MAX_ROBOTS) {
                let truth = GroundTruth {
                    robot: robot.name.clone(),
                    step: status.step,
                    time_s: status.time_s,
                    at: robot.at,
                };
                self.out
                    .log(&self.truth_topic, &convert::truth(&truth, now));
            }
            self.robots = Some(status.robots);
        }
    }
}

/// True positions, estimates, missions and driven paths.
struct Robots {
    out: Arc<Outputs>,
    topics: RobotTopics,
    missions: BTreeMap<String, Mission>,
    driven: BTreeMap<String, DrivenPath>,
    driven_dirty: bool,
    full_warned: bool,
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
                    Ok(sample) => {
                        if let Some(p) = decode_sample::<PositionEstimate>(&self.out, &sample) {
                            self.out.log(&self.topics.estimate, &convert::estimate(&p, Timestamp::now()));
                        }
                    }
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

    /// Whether a robot may get per-robot state (a new one only below [`MAX_ROBOTS`]).
    fn admits(&mut self, robot: &str, known: bool, key: &str) -> bool {
        if known {
            return true;
        }
        if self.missions.len().max(self.driven.len()) < MAX_ROBOTS {
            return true;
        }
        if !self.full_warned {
            self.full_warned = true;
            self.out.counters.dropped(
                key,
                &format!("more than {MAX_ROBOTS} robots; robot '{robot}' has no path drawn"),
            );
        }
        false
    }

    fn on_truth(&mut self, sample: &Sample) {
        let Some(t) = decode_sample::<GroundTruth>(&self.out, sample) else {
            return;
        };
        self.out
            .log(&self.topics.truth, &convert::truth(&t, Timestamp::now()));
        let known = self.driven.contains_key(&t.robot);
        if self.admits(&t.robot, known, sample.key_expr().as_str()) {
            let path = self
                .driven
                .entry(t.robot.clone())
                .or_insert_with(|| DrivenPath::new(DRIVEN_POINTS, DRIVEN_STEP_M));
            self.driven_dirty |= path.push(t.at);
        }
    }

    fn on_mission(&mut self, sample: &Sample) {
        let Some(m) = decode_sample::<Mission>(&self.out, sample) else {
            return;
        };
        let known = self.missions.contains_key(&m.robot);
        if !self.admits(&m.robot, known, sample.key_expr().as_str()) {
            return;
        }
        self.missions.insert(m.robot.clone(), m);
        // The whole state, so the latched message alone shows every robot's mission.
        let update = convert::missions(self.missions.values(), Timestamp::now());
        self.out.log(&self.topics.mission, &update);
    }

    fn log_driven(&mut self) {
        let update = convert::driven(
            self.driven.iter().map(|(r, p)| (r.as_str(), p)),
            Timestamp::now(),
        );
        self.out.log(&self.topics.driven, &update);
        self.driven_dirty = false;
    }
}
