//! Waiting for a service's liveliness token: how a client (the stack, the tests, a
//! check script) knows a service is up before asking it anything.

use std::time::Duration;

/// Why waiting for a liveliness token ended without it.
#[derive(Debug, thiserror::Error)]
pub enum LivelinessWait {
    #[error("no liveliness token appeared in time")]
    Timeout,
    #[error("zenoh: {0}")]
    Zenoh(String),
}

/// Waits until a liveliness token matching `key` exists (one that exists already
/// counts: the subscriber asks for history).
pub async fn wait_for_liveliness(
    session: &zenoh::Session,
    key: &str,
    timeout: Duration,
) -> Result<(), LivelinessWait> {
    let subscriber = session
        .liveliness()
        .declare_subscriber(key)
        .history(true)
        .await
        .map_err(|e| LivelinessWait::Zenoh(e.to_string()))?;
    match tokio::time::timeout(timeout, subscriber.recv_async()).await {
        Ok(Ok(_)) => Ok(()),
        Ok(Err(e)) => Err(LivelinessWait::Zenoh(e.to_string())),
        Err(_) => Err(LivelinessWait::Timeout),
    }
}
