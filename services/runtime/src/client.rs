//! The asking end of a query: send a roam message with a `get`, get back the reply
//! message or the service's structured error.

use std::time::Duration;

use roam_proto::{decode, encode, DecodeError, ErrorReply, Message};
use zenoh::Session;

/// Why a request got no usable answer.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    #[error("the service refused the request: {0}")]
    Refused(ErrorReply),
    #[error("no reply on '{key}' within {timeout:?}: is a service answering there (check `<root>/@live/**`)?")]
    NoReply { key: String, timeout: Duration },
    #[error("the reply on '{key}' could not be decoded: {source}")]
    Decode { key: String, source: DecodeError },
    #[error("the query on '{key}' failed in Zenoh: {reason}")]
    Zenoh { key: String, reason: String },
}

impl ClientError {
    /// The service's error reply, if the service answered with one.
    pub fn refusal(&self) -> Option<&ErrorReply> {
        match self {
            ClientError::Refused(reply) => Some(reply),
            _ => None,
        }
    }
}

/// Sends queries on one session with one timeout.
#[derive(Debug, Clone)]
pub struct Requester {
    session: Session,
    timeout: Duration,
}

impl Requester {
    pub fn new(session: Session, timeout: Duration) -> Self {
        Requester { session, timeout }
    }

    pub fn session(&self) -> &Session {
        &self.session
    }

    /// Sends `request` (or no payload) to `key` and decodes the first reply as `R`.
    pub async fn request<Q: Message, R: Message>(
        &self,
        key: &str,
        request: Option<&Q>,
    ) -> Result<R, ClientError> {
        let payload = request.map(encode);
        self.request_raw(key, payload).await
    }

    /// Sends raw bytes (for clients that build their own payloads, and for tests of
    /// malformed input) and decodes the first reply as `R`.
    pub async fn request_raw<R: Message>(
        &self,
        key: &str,
        payload: Option<Vec<u8>>,
    ) -> Result<R, ClientError> {
        let zenoh_err = |e: zenoh::Error| ClientError::Zenoh {
            key: key.to_owned(),
            reason: e.to_string(),
        };
        let mut get = self.session.get(key).timeout(self.timeout);
        if let Some(bytes) = payload {
            get = get.payload(bytes);
        }
        let replies = get.await.map_err(zenoh_err)?;
        // Zenoh ends the reply stream at its own timeout; ours guards against a hang.
        let reply =
            tokio::time::timeout(self.timeout + Duration::from_secs(1), replies.recv_async())
                .await
                .ok()
                .and_then(Result::ok)
                .ok_or_else(|| ClientError::NoReply {
                    key: key.to_owned(),
                    timeout: self.timeout,
                })?;
        match reply.result() {
            Ok(sample) => {
                decode(&sample.payload().to_bytes()).map_err(|source| ClientError::Decode {
                    key: key.to_owned(),
                    source,
                })
            }
            Err(error) => {
                let refusal: ErrorReply =
                    decode(&error.payload().to_bytes()).map_err(|source| ClientError::Decode {
                        key: key.to_owned(),
                        source,
                    })?;
                Err(ClientError::Refused(refusal))
            }
        }
    }
}
