//! Publishing a message: one place for put, congestion control and the warning when it
//! fails, so every call site names how its publication meets a congested link.
//!
//! Zenoh's `put` drops a sample by default when the transport's queue is full. That is
//! right for a stream whose next sample supersedes this one, and wrong for a sample a
//! subscriber must not miss (a command, a mission, a map version): [`Delivery`] makes
//! the choice explicit at each call.

use roam_proto::{encode, Message};
use zenoh::bytes::ZBytes;
use zenoh::qos::CongestionControl;
use zenoh::Wait;

/// How a publication meets a full transport queue.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delivery {
    /// Wait until the transport takes the sample: for state a subscriber must not miss
    /// (commands, missions, reports, layers, the sim's readings in lock-step).
    Reliable,
    /// Drop the sample when the queue is full: for streams whose next sample supersedes
    /// this one (estimates at the ranging rate, a plan's progress, a best-effort
    /// cancel of an abandoned plan).
    Latest,
}

impl Delivery {
    fn congestion_control(self) -> CongestionControl {
        match self {
            Delivery::Reliable => CongestionControl::Block,
            Delivery::Latest => CongestionControl::Drop,
        }
    }
}

/// Publishes `message` on `key`; a failure is logged (a publisher has no one to tell)
/// and returned as `false`.
pub async fn publish<T: Message>(
    session: &zenoh::Session,
    key: &str,
    message: &T,
    delivery: Delivery,
) -> bool {
    publish_bytes(session, key, encode(message), delivery).await
}

/// [`publish`] for bytes already encoded (a layer encoded once for many keys).
pub async fn publish_bytes(
    session: &zenoh::Session,
    key: &str,
    bytes: impl Into<ZBytes>,
    delivery: Delivery,
) -> bool {
    let sent = session
        .put(key, bytes)
        .congestion_control(delivery.congestion_control())
        .await;
    logged(key, sent)
}

/// [`publish`] from synchronous code (a blocking task, a callback).
pub fn publish_wait<T: Message>(
    session: &zenoh::Session,
    key: &str,
    message: &T,
    delivery: Delivery,
) -> bool {
    let sent = session
        .put(key, encode(message))
        .congestion_control(delivery.congestion_control())
        .wait();
    logged(key, sent)
}

fn logged(key: &str, sent: zenoh::Result<()>) -> bool {
    match sent {
        Ok(()) => true,
        Err(e) => {
            tracing::warn!(%key, "publication failed: {e}");
            false
        }
    }
}
