//! roam → ROS 2: follows the map server's layers and the robots' estimates, missions and
//! true positions on roam's keys, and publishes them as ROS topics.
//!
//! Layers: followed by `roam_runtime::layer_follow` (each publication on
//! `<root>/map/layer/*`, each delta on `<root>/map/delta/*` applied to the layer last
//! published when it is the delta's base version, else the whole layer fetched, and at
//! start and every [`roam_runtime::layer_follow::REFRESH_PERIOD`] a look at `<root>/map/layers`), each of
//! [`LAYER_TOPICS`] published as its grid. Robots: their
//! estimates (`/<robot>/pose`), missions (`/<robot>/plan`) and true positions (the path
//! driven, `/<robot>/driven`, at most every [`DRIVEN_PERIOD`]); each estimate is also
//! the transform `map → <robot>/base_link` on `/tf`.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Duration;

use roam_proto::controller::{Mission, MAX_MISSION_BYTES, MAX_WAYPOINTS};
use roam_proto::localization::PositionEstimate;
use roam_proto::map::{Layer, LayerList};
use roam_proto::sim::GroundTruth;
use roam_proto::{decode, keys, Message};
use roam_runtime::layer_follow::{follow_layers, LayerSink};
use roam_runtime::{ClientError, FleetStreams, LatestSamples, Requester};
use tokio::time::MissedTickBehavior;
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;
use zenoh::Session;

use super::output::Output;
use super::poses::RobotPoses;
use crate::convert::{self, LAYER_TOPICS};
use crate::msg::Time;
use crate::names::{self, Qos};
use crate::{attachment, types};

/// How long one of its queries may take.
const QUERY_TIMEOUT: Duration = Duration::from_secs(5);
/// The driven paths are published at most this often.
pub const DRIVEN_PERIOD: Duration = Duration::from_millis(250);
/// The most points kept per driven path, and the least distance between two of them.
pub const DRIVEN_POINTS: usize = 4096;
pub const DRIVEN_STEP_M: f64 = 0.05;
/// tf2's topic, relative to the node's namespace as tf2_ros resolves it (`/tf` in the
/// root namespace).
pub const TF_TOPIC: &str = "tf";
pub use super::poses::MAX_ROBOTS;
/// The largest layer read: the map server's largest (16,777,216 f32 cells in base64)
/// and its envelope.
pub const MAX_LAYER_BYTES: usize = roam_runtime::service::DEFAULT_MAX_SAMPLE_BYTES;
const MAX_ESTIMATE_BYTES: usize = 64 * 1024;
const MAX_TRUTH_BYTES: usize = 4 * 1024;

type Ring = LatestSamples;

fn now() -> Time {
    Time::from_nanos(attachment::now_ns())
}

/// Decodes a sample of at most `max` bytes, or logs the refusal.
fn decode_sample<T: Message>(out: &Output, sample: &Sample, max: usize) -> Option<T> {
    let key = sample.key_expr().as_str();
    let bytes = sample.payload().len();
    if bytes > max {
        out.refuse(
            key,
            &format!(
                "{bytes} bytes; a '{}' is read only up to {max} bytes",
                T::KIND
            ),
        );
        return None;
    }
    match decode::<T>(&sample.payload().to_bytes()) {
        Ok(message) => Some(message),
        Err(e) => {
            out.refuse(
                key,
                &roam_proto::excerpt::excerpt_n(&e.to_string(), 256).to_string(),
            );
            None
        }
    }
}

pub(crate) async fn run(
    session: Session,
    root: String,
    subscriptions: FleetStreams,
    out: Arc<Output>,
    poses: Arc<RobotPoses>,
    cancel: CancellationToken,
) {
    let FleetStreams {
        layers,
        deltas,
        estimate,
        mission,
        truth,
    } = subscriptions;
    let mut world = Layers {
        out: out.clone(),
        root: root.clone(),
        requester: Requester::new(session, QUERY_TIMEOUT),
        published: BTreeMap::new(),
    };
    let world_root = root.clone();
    let robots = Robots {
        out,
        root,
        poses,
        driven: BTreeMap::new(),
    };
    tokio::join!(
        follow_layers(&mut world, &world_root, layers, deltas, cancel.clone()),
        robots.run(estimate, mission, truth, cancel)
    );
}

struct Layers {
    out: Arc<Output>,
    root: String,
    requester: Requester,
    /// Each layer published, as published: deltas apply to it.
    published: BTreeMap<String, Layer>,
}

impl LayerSink for Layers {
    type Error = ClientError;
    const MAX_LAYER_BYTES: usize = MAX_LAYER_BYTES;
    const MAX_LAYERS: usize = LAYER_TOPICS.len();

    /// The layers with a ROS topic ([`LAYER_TOPICS`]).
    fn follows(&self, name: &str) -> bool {
        LAYER_TOPICS.iter().any(|(layer, ..)| *layer == name)
    }

    fn held(&self, name: &str) -> Option<u64> {
        self.published.get(name).map(|l| l.version)
    }

    fn take_kept(&mut self, name: &str) -> Option<Layer> {
        self.published.remove(name)
    }

    /// Publishes a layer as its topic's grid, and keeps it.
    async fn show(&mut self, layer: Layer, _published: bool) {
        let Some((_, topic, scale)) = LAYER_TOPICS.iter().find(|(name, ..)| *name == layer.name)
        else {
            return;
        };
        match convert::layer_to_grid(&layer, *scale, now()) {
            Ok(grid) => {
                self.out
                    .publish(topic, types::OCCUPANCY_GRID, Qos::LATCHED, &grid)
                    .await;
                tracing::debug!(layer = %layer.name, version = layer.version, "roam ros2: layer published");
                self.published.insert(layer.name.clone(), layer);
            }
            Err(e) => self
                .out
                .refuse(&keys::map_layer(&self.root, &layer.name), &e.to_string()),
        }
    }

    fn decode<T: Message>(&self, sample: &Sample, max: usize) -> Option<T> {
        decode_sample(&self.out, sample, max)
    }

    fn refuse(&self, key: &str, reason: &str) {
        self.out.refuse(key, reason);
    }

    fn unread(&self, key: &str, error: &ClientError) {
        tracing::debug!(%key, "roam ros2: layer not fetched: {error}");
    }

    async fn query_layer(&self, key: &str) -> Result<Layer, ClientError> {
        self.requester.request::<Layer, Layer>(key, None).await
    }

    async fn query_index(&self, key: &str) -> Result<LayerList, ClientError> {
        self.requester
            .request::<LayerList, LayerList>(key, None)
            .await
    }
}

/// A robot's driven path: its true positions, at least [`DRIVEN_STEP_M`] apart, the
/// last [`DRIVEN_POINTS`].
#[derive(Debug, Default)]
struct Driven {
    points: std::collections::VecDeque<[f64; 2]>,
    dirty: bool,
}

impl Driven {
    fn push(&mut self, at: [f64; 2]) {
        let far = self
            .points
            .back()
            .is_none_or(|p| (p[0] - at[0]).hypot(p[1] - at[1]) >= DRIVEN_STEP_M);
        if far && at.iter().all(|v| v.is_finite()) {
            if self.points.len() == DRIVEN_POINTS {
                self.points.pop_front();
            }
            self.points.push_back(at);
            self.dirty = true;
        }
    }
}

struct Robots {
    out: Arc<Output>,
    root: String,
    /// The latest estimates, for ComputePathToPose goals from the robot's pose.
    poses: Arc<RobotPoses>,
    driven: BTreeMap<String, Driven>,
}

impl Robots {
    async fn run(mut self, estimate: Ring, mission: Ring, truth: Ring, cancel: CancellationToken) {
        let mut tick = tokio::time::interval(DRIVEN_PERIOD);
        tick.set_missed_tick_behavior(MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = mission.recv_async() => match sample {
                    Ok(sample) => self.on_mission(&sample).await,
                    Err(_) => break,
                },
                sample = estimate.recv_async() => match sample {
                    Ok(sample) => self.on_estimate(&sample).await,
                    Err(_) => break,
                },
                sample = truth.recv_async() => match sample {
                    Ok(sample) => self.on_truth(&sample),
                    Err(_) => break,
                },
                _ = tick.tick() => self.publish_driven().await,
            }
        }
    }

    /// The robot a message is about, when its key names it, its body agrees, and it is a
    /// valid ROS name segment (`r1`, not `robot-1`: ROS names have no '-').
    fn robot<'k>(&self, key: &'k str, body_robot: &str) -> Option<&'k str> {
        let robot = match roam_runtime::routing::robot_for(&self.root, key, body_robot) {
            Ok(robot) => robot,
            Err(e) => {
                self.out.refuse(key, &e.to_string());
                return None;
            }
        };
        if let Err(e) = names::qualify(&self.out.node().namespace, &format!("{robot}/plan")) {
            self.out
                .refuse(key, &format!("robot '{robot}' has no ROS topic: {e}"));
            return None;
        }
        Some(robot)
    }

    async fn on_mission(&mut self, sample: &Sample) {
        let Some(m) = decode_sample::<Mission>(&self.out, sample, MAX_MISSION_BYTES) else {
            return;
        };
        let key = sample.key_expr().as_str();
        let Some(robot) = self.robot(key, &m.robot) else {
            return;
        };
        if m.waypoints.len() > MAX_WAYPOINTS || m.waypoints.iter().flatten().any(|v| !v.is_finite())
        {
            return self.out.refuse(key, &format!("a mission of at most {MAX_WAYPOINTS} finite waypoints is published; this one is not"));
        }
        // A mission without waypoints (the executive's "stay") is not a plan: published,
        // it would be the latched sample a late subscriber gets instead of the last path.
        if m.waypoints.is_empty() {
            return;
        }
        let path = convert::path(&m.waypoints, now());
        self.out
            .publish(&format!("{robot}/plan"), types::PATH, Qos::LATCHED, &path)
            .await;
    }

    async fn on_estimate(&mut self, sample: &Sample) {
        let Some(e) = decode_sample::<PositionEstimate>(&self.out, sample, MAX_ESTIMATE_BYTES)
        else {
            return;
        };
        let key = sample.key_expr().as_str();
        let Some(robot) = self.robot(key, &e.robot) else {
            return;
        };
        if !e.position.iter().all(|v| v.is_finite()) {
            return self
                .out
                .refuse(key, "an estimate that is not a finite position");
        }
        let stamp = now();
        let pose = convert::estimate_pose(&e, stamp);
        self.out
            .publish(
                &format!("{robot}/pose"),
                types::POSE_WITH_COVARIANCE_STAMPED,
                Qos::STREAM,
                &pose,
            )
            .await;
        let transform = convert::estimate_transform(robot, &e, stamp);
        self.out
            .publish(TF_TOPIC, types::TF_MESSAGE, Qos::TF, &transform)
            .await;
        self.poses.record(robot, e.position);
    }

    fn on_truth(&mut self, sample: &Sample) {
        let Some(t) = decode_sample::<GroundTruth>(&self.out, sample, MAX_TRUTH_BYTES) else {
            return;
        };
        let key = sample.key_expr().as_str();
        let Some(robot) = self.robot(key, &t.robot) else {
            return;
        };
        if !self.driven.contains_key(robot) && self.driven.len() >= MAX_ROBOTS {
            return self.out.refuse(
                key,
                &format!("more than {MAX_ROBOTS} robots; this one's driven path is not published"),
            );
        }
        self.driven.entry(robot.to_owned()).or_default().push(t.at);
    }

    async fn publish_driven(&mut self) {
        let stamp = now();
        for (robot, driven) in self.driven.iter_mut() {
            if driven.dirty {
                driven.dirty = false;
                let points: Vec<[f64; 2]> = driven.points.iter().copied().collect();
                let path = convert::path(&points, stamp);
                self.out
                    .publish(&format!("{robot}/driven"), types::PATH, Qos::LATCHED, &path)
                    .await;
            }
        }
    }
}
