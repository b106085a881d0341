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
