//! Subscribing to streams whose newest samples matter most.
//!
//! Zenoh's default receive channel is a FIFO of 256 samples that blocks the session's
//! delivery when its reader falls behind: one slow consumer then stalls every
//! subscription of the session. A reader that only needs the newest state (the maps, the
//! robots' positions) takes a ring instead, which drops the oldest sample when full.

use zenoh::handlers::{RingChannel, RingChannelHandler};
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

/// A subscriber that keeps the newest samples and drops the oldest when full.
pub type LatestSamples = Subscriber<RingChannelHandler<Sample>>;

/// Subscribes to `key` keeping at most the `capacity` newest samples.
pub async fn subscribe_latest(
    session: &zenoh::Session,
    key: &str,
    capacity: usize,
) -> Result<LatestSamples, zenoh::Error> {
    session
        .declare_subscriber(key.to_owned())
        .with(RingChannel::new(capacity))
        .await
}

/// The streams a follower of the whole fleet reads (the live view, the ROS 2 node):
/// every map layer and layer delta, and every robot's true position, estimate and
/// mission, each a ring of its newest samples.
pub struct FleetStreams {
    pub layers: LatestSamples,
    /// Small changes of layers (`<root>/map/delta/*`): a follower holding the layer at
    /// a delta's base version applies it, any other gets the whole layer.
    pub deltas: LatestSamples,
    pub truth: LatestSamples,
    pub estimate: LatestSamples,
    pub mission: LatestSamples,
}

impl std::fmt::Debug for FleetStreams {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FleetStreams")
            .field("layers", &self.layers.key_expr().as_str())
            .field("deltas", &self.deltas.key_expr().as_str())
            .field("truth", &self.truth.key_expr().as_str())
            .field("estimate", &self.estimate.key_expr().as_str())
            .field("mission", &self.mission.key_expr().as_str())
            .finish()
    }
}

impl FleetStreams {
    /// Layers the layer ring holds before the oldest go (a follower fetches a dropped
    /// one again at its next refresh of the map index, whose version check sees it
    /// missing).
    pub const LAYER_QUEUE: usize = 8;
    /// Deltas the delta ring holds before the oldest go (a follower that misses one
    /// sees the next one's base version differ from its own, and gets the whole layer).
    pub const DELTA_QUEUE: usize = 32;
    /// Samples each robot ring holds before the oldest go.
    pub const ROBOT_QUEUE: usize = 256;

    /// Declares the four subscriptions under `root`; declare them before anything that
    /// should be seen is published.
    pub async fn declare(
        session: &zenoh::Session,
        root: &str,
    ) -> Result<Self, crate::service::ServiceError> {
        use roam_proto::keys;
        let ring = |key: String, capacity: usize| async move {
            subscribe_latest(session, &key, capacity)
                .await
                .map_err(|e| crate::service::ServiceError::Declare {
                    what: "subscriber",
                    key,
                    reason: e.to_string(),
                })
        };
        Ok(FleetStreams {
            layers: ring(keys::map_layer_any(root), Self::LAYER_QUEUE).await?,
            deltas: ring(keys::map_delta_any(root), Self::DELTA_QUEUE).await?,
            // `robot_truth` with the robot `*`: every robot's true position.
            truth: ring(keys::robot_truth(root, "*"), Self::ROBOT_QUEUE).await?,
            estimate: ring(keys::robot_estimate_any(root), Self::ROBOT_QUEUE).await?,
            mission: ring(keys::robot_mission_any(root), Self::ROBOT_QUEUE).await?,
        })
    }
}
