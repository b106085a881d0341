//! Where roam's ROS messages go: rmw_zenoh publishers (declared on first use, each with
//! its liveliness token, its GID and its sequence numbers) and the rosbag2 recording.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;
use std::time::Duration;

use serde::Serialize;
use zenoh::handlers::FifoChannelHandler;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::qos::{CongestionControl, Reliability as ZReliability};
use zenoh::sample::Sample;
use zenoh::Session;
use zenoh_ext::{AdvancedPublisher, AdvancedPublisherBuilderExt, CacheConfig, MissDetectionConfig};

use super::error::Ros2Error;
use crate::attachment::{self, Attachment};
use crate::bag::{Bag, BagSummary};
use crate::names::{self, Durability, EntityKind, NodeInfo, Qos};
use crate::wire::{self, Endpoint};

/// rmw_zenoh's heartbeat period for reliable transient-local publishers
/// (`SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD`), so late subscribers recover lost samples.
const HEARTBEAT: Duration = Duration::from_millis(500);

/// The most topics one node publishes (5 layers and 3 per robot for 256 robots, and room).
pub const MAX_TOPICS: usize = 1024;

struct RosPublisher {
    endpoint: Endpoint,
    publisher: AdvancedPublisher<'static>,
    _token: LivelinessToken,
    sequence: i64,
}

/// Every message roam sends to ROS 2 goes through here.
pub struct Output {
    session: Session,
    node: NodeInfo,
    offer: bool,
    next_id: AtomicU32,
    publishers: tokio::sync::Mutex<BTreeMap<String, RosPublisher>>,
    bag: Mutex<Option<Bag>>,
    /// A topic roam takes from ROS 2 (`--ros2-map`) is not also published by roam: its
    /// publisher there is the ROS node's, and roam's own map would come back to it.
    taken: Option<String>,
    pub(crate) warnings: roam_runtime::warn_limit::WarnLimiter,
}

impl std::fmt::Debug for Output {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Output")
            .field("node", &self.node)
            .field("offer", &self.offer)
            .finish_non_exhaustive()
    }
}

impl Output {
    pub(crate) fn new(
        session: Session,
        node: NodeInfo,
        offer: bool,
        bag: Option<Bag>,
        taken: Option<String>,
    ) -> Output {
        Output {
            taken,
            session,
            node,
            offer,
            // 0 is the node's own id.
            next_id: AtomicU32::new(1),
            publishers: tokio::sync::Mutex::new(BTreeMap::new()),
            bag: Mutex::new(bag),
            warnings: roam_runtime::warn_limit::WarnLimiter::new(),
        }
    }

    pub(crate) fn session(&self) -> &Session {
        &self.session
    }

    pub(crate) fn node(&self) -> &NodeInfo {
        &self.node
    }

    /// Logs a refusal at most a few times per 10 s per source (with the count of the
    /// others), so a flood of bad input is a few lines, not a flood of lines.
    pub(crate) fn refuse(&self, source: &str, reason: &str) {
        if let Some(suppressed) = self.warnings.allow(source) {
            if suppressed > 0 {
                tracing::warn!(%source, suppressed, "roam ros2: refused: {reason}");
            } else {
                tracing::warn!(%source, "roam ros2: refused: {reason}");
            }
        }
    }

    /// The endpoint `name` of this node with a fresh entity id.
    pub(crate) fn endpoint(
        &self,
        kind: EntityKind,
        name: &str,
        ros_type: &'static str,
        qos: Qos,
    ) -> Result<Endpoint, wire::EndpointError> {
        let id = self.next_id.fetch_add(1, Ordering::Relaxed);
        wire::endpoint(&self.node, id, kind, name, ros_type, qos)
    }

    /// [`Output::endpoint`], a failure named as declaring `what` on `name`.
    pub(crate) fn declared_endpoint(
        &self,
        what: &'static str,
        kind: EntityKind,
        name: &str,
        ros_type: &'static str,
        qos: Qos,
    ) -> Result<Endpoint, Ros2Error> {
        self.endpoint(kind, name, ros_type, qos)
            .map_err(|e| Ros2Error::Declare {
                what,
                key: name.to_owned(),
                reason: e.to_string(),
            })
    }

    /// A plain subscription to topic `name` with its `MS` token (kept alive by the
    /// caller): what the node reads from ROS 2 as a stream.
    pub(crate) async fn subscribe(
        &self,
        what: &'static str,
        name: &str,
        ros_type: &'static str,
        qos: Qos,
    ) -> Result<
        (
            Endpoint,
            Subscriber<FifoChannelHandler<Sample>>,
            LivelinessToken,
        ),
        Ros2Error,
    > {
        let endpoint =
            self.declared_endpoint(what, EntityKind::Subscription, name, ros_type, qos)?;
        let subscriber = self
            .session
            .declare_subscriber(endpoint.key.clone())
            .await
            .map_err(|e| Ros2Error::Declare {
                what,
                key: endpoint.key.clone(),
                reason: e.to_string(),
            })?;
        let token = self.token(&endpoint.token).await?;
        Ok((endpoint, subscriber, token))
    }

    /// Declares a liveliness token, naming the key when it fails.
    pub(crate) async fn token(&self, key: &str) -> Result<LivelinessToken, Ros2Error> {
        self.session
            .liveliness()
            .declare_token(key.to_owned())
            .await
            .map_err(|e| Ros2Error::Declare {
                what: "liveliness token",
                key: key.to_owned(),
                reason: e.to_string(),
            })
    }

    /// The node's own token (`NN`).
    pub(crate) async fn declare_node(&self) -> Result<LivelinessToken, Ros2Error> {
        self.token(&names::node_token(&self.node)).await
    }

    async fn declare_publisher(
        &self,
        name: &str,
        ros_type: &'static str,
        qos: Qos,
    ) -> Result<RosPublisher, String> {
        let endpoint = self
            .endpoint(EntityKind::Publisher, name, ros_type, qos)
            .map_err(|e| e.to_string())?;
        let builder = self
            .session
            .declare_publisher(endpoint.key.clone())
            .reliability(ZReliability::Reliable);
        // As rmw_zenoh: a transient-local publisher keeps `depth` samples in a cache that
        // late AdvancedSubscribers query, detects them through liveliness, and sends
        // heartbeats so they recover a lost sample; maps are large and delivered (Block).
        let publisher = match qos.durability {
            Durability::TransientLocal => {
                builder
                    .congestion_control(CongestionControl::Block)
                    .sample_miss_detection(
                        MissDetectionConfig::default().sporadic_heartbeat(HEARTBEAT),
                    )
                    .cache(CacheConfig::default().max_samples(qos.depth as usize))
                    .publisher_detection()
                    .await
            }
            Durability::Volatile => builder.advanced().await,
        }
        .map_err(|e| format!("declaring the publisher on '{}': {e}", endpoint.key))?;
        let token = self
            .token(&endpoint.token)
            .await
            .map_err(|e| e.to_string())?;
        Ok(RosPublisher {
            endpoint,
            publisher,
            _token: token,
            sequence: 0,
        })
    }

    /// Declares topic `name`'s publisher (and its token) before its first message: an
    /// action server's feedback and status publishers are part of what tells a ROS 2
    /// client the server is there (`rcl_action_server_is_available`).
    pub(crate) async fn declare(
        &self,
        name: &str,
        ros_type: &'static str,
        qos: Qos,
    ) -> Result<(), Ros2Error> {
        if !self.offer {
            return Ok(());
        }
        let mut publishers = self.publishers.lock().await;
        self.ensure_publisher(&mut publishers, name, ros_type, qos)
            .await
            .map_err(|reason| Ros2Error::Declare {
                what: "publisher",
                key: name.to_owned(),
                reason,
            })
    }

    /// Topic `name`'s publisher, declared if it is not yet (up to [`MAX_TOPICS`]).
    async fn ensure_publisher(
        &self,
        publishers: &mut BTreeMap<String, RosPublisher>,
        name: &str,
        ros_type: &'static str,
        qos: Qos,
    ) -> Result<(), String> {
        if publishers.contains_key(name) {
            return Ok(());
        }
        if publishers.len() >= MAX_TOPICS {
            return Err(format!("more than {MAX_TOPICS} topics; not published"));
        }
        let publisher = self.declare_publisher(name, ros_type, qos).await?;
        tracing::debug!(topic = name, key = %publisher.endpoint.key, "roam ros2: publisher declared");
        publishers.insert(name.to_owned(), publisher);
        Ok(())
    }

    /// Sends `message` on topic `name` (relative to the node's namespace) and records it;
    /// the publisher is declared at the first message. Failures are logged, never fatal.
    pub(crate) async fn publish<T: Serialize>(
        &self,
        name: &str,
        ros_type: &'static str,
        qos: Qos,
        message: &T,
    ) {
        let bytes = match crate::cdr::encode(message) {
            Ok(bytes) => bytes,
            Err(e) => return tracing::warn!(topic = name, "roam ros2: not sent: {e}"),
        };
        let now = attachment::now_ns();
        let taken =
            self.taken.is_some() && names::qualify(&self.node.namespace, name).ok() == self.taken;
        if self.offer && !taken {
            let mut publishers = self.publishers.lock().await;
            if let Err(e) = self
                .ensure_publisher(&mut publishers, name, ros_type, qos)
                .await
            {
                return self.refuse(name, &e);
            }
            if let Some(p) = publishers.get_mut(name) {
                p.sequence += 1;
                let attachment = Attachment {
                    sequence_number: p.sequence,
                    source_timestamp_ns: now,
                    gid: p.endpoint.gid,
                };
                if let Err(e) = p
                    .publisher
                    .put(bytes.clone())
                    .attachment(attachment.to_bytes().to_vec())
                    .await
                {
                    tracing::warn!(topic = name, "roam ros2: put failed: {e}");
                }
            }
        }
        self.record(name, ros_type, qos, now, &bytes);
    }

    fn record(&self, name: &str, ros_type: &'static str, qos: Qos, now: i64, bytes: &[u8]) {
        let mut bag = roam_runtime::lock(&self.bag);
        if let Some(recording) = bag.as_mut() {
            let topic = match names::qualify(&self.node.namespace, name) {
                Ok(topic) => topic,
                Err(e) => return self.refuse(name, &e.to_string()),
            };
            if let Err(e) = recording.write(&topic, ros_type, qos, now.max(0) as u64, bytes) {
                tracing::warn!(%topic, "roam ros2: not recorded: {e}");
            }
        }
    }

    /// Completes the recording, if there is one.
    pub(crate) fn finish_bag(&self) -> Result<Option<BagSummary>, crate::bag::BagError> {
        let bag = roam_runtime::lock(&self.bag).take();
        bag.map(Bag::finish).transpose()
    }
}
