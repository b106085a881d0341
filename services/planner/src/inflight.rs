//! The plans an instance has in flight, by the key their cancel comes on (which names
//! the request id; [`crate::scope`]), and who may cancel them.
//!
//! A plan is registered with the `cancel_token` its request carried. A cancel is
//! honoured only when it brings the same token (compared in constant time,
//! [`tokens_match`]); a cancel with a wrong token or none is refused, and a plan whose
//! request had no token cannot be cancelled at all: it runs to its generations or its
//! deadline. Only the instance itself stops every plan at once, when it shuts down.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use tokio_util::sync::CancellationToken;

use crate::token::tokens_match;

struct Entry {
    stop: Arc<AtomicBool>,
    /// Cancelled with `stop`: wakes a request waiting in the queue.
    wake: CancellationToken,
    token: Option<String>,
}

/// What a cancel did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CancelVerdict {
    /// The token matched: the plan stops at its next generation.
    Cancelled,
    /// The cancel's token is not the plan's: ignored.
    WrongToken,
    /// The cancel brought no token: ignored.
    MissingToken,
    /// The plan's request had no token, so no cancel can stop it: ignored.
    NotCancellable,
    /// No plan with that id is in flight here (finished, or on another instance).
    Unknown,
}

/// The request id is already being planned on this instance (under the same key).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the request id is already being planned")]
pub struct AlreadyInFlight;

/// The table of plans in flight.
#[derive(Default)]
pub struct InFlight {
    plans: Mutex<HashMap<String, Entry>>,
}

impl std::fmt::Debug for InFlight {
    // Tokens are secrets: never in a debug print.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InFlight")
            .field("plans", &self.lock().len())
            .finish()
    }
}

impl InFlight {
    fn lock(&self) -> MutexGuard<'_, HashMap<String, Entry>> {
        roam_runtime::lock(&self.plans)
    }

    /// Registers a plan (queued or planning) under the key its cancel comes on;
    /// returns the flag that stops it and the token that wakes it while it waits in the
    /// queue. A key already in flight (the same request id, asked the same way) is
    /// refused.
    pub fn register(
        &self,
        key: &str,
        token: Option<String>,
    ) -> Result<(Arc<AtomicBool>, CancellationToken), AlreadyInFlight> {
        let mut plans = self.lock();
        if plans.contains_key(key) {
            return Err(AlreadyInFlight);
        }
        let stop = Arc::new(AtomicBool::new(false));
        let wake = CancellationToken::new();
        plans.insert(
            key.to_owned(),
            Entry {
                stop: stop.clone(),
                wake: wake.clone(),
                token,
            },
        );
        Ok((stop, wake))
    }

    /// Forgets a plan (it has ended).
    pub fn remove(&self, key: &str) {
        self.lock().remove(key);
    }

    /// A cancel heard on `key` with `token`: stops the plan registered under that key
    /// only if the token is the one its request carried.
    pub fn cancel(&self, key: &str, token: Option<&str>) -> CancelVerdict {
        let plans = self.lock();
        let Some(entry) = plans.get(key) else {
            return CancelVerdict::Unknown;
        };
        let Some(expected) = &entry.token else {
            return CancelVerdict::NotCancellable;
        };
        let Some(given) = token else {
            return CancelVerdict::MissingToken;
        };
        if tokens_match(expected, given) {
            entry.stop.store(true, Ordering::Relaxed);
            entry.wake.cancel();
            CancelVerdict::Cancelled
        } else {
            CancelVerdict::WrongToken
        }
    }

    /// Stops every plan in flight (the instance is shutting down).
    pub fn stop_all(&self) {
        for entry in self.lock().values() {
            entry.stop.store(true, Ordering::Relaxed);
            entry.wake.cancel();
        }
    }

    pub fn len(&self) -> usize {
        self.lock().len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOKEN: &str = "0123456789abcdef0123456789abcdef";

    #[test]
    fn only_the_requesters_token_cancels() {
        let inflight = InFlight::default();
        let (stop, wake) = inflight
            .register("trip", Some(TOKEN.into()))
            .expect("registered");
        assert_eq!(
            inflight.cancel("trip", Some("0123456789abcdef0123456789abcdee")),
            CancelVerdict::WrongToken
        );
        assert_eq!(inflight.cancel("trip", None), CancelVerdict::MissingToken);
        assert_eq!(
            inflight.cancel("other", Some(TOKEN)),
            CancelVerdict::Unknown
        );
        assert!(!stop.load(Ordering::Relaxed), "refused cancels do nothing");
        assert!(!wake.is_cancelled());
        assert_eq!(
            inflight.cancel("trip", Some(TOKEN)),
            CancelVerdict::Cancelled
        );
        assert!(stop.load(Ordering::Relaxed));
        assert!(wake.is_cancelled(), "a queued request wakes");
    }

    #[test]
    fn a_plan_without_a_token_cannot_be_cancelled_but_stops_at_shutdown() {
        let inflight = InFlight::default();
        let (stop, wake) = inflight.register("open", None).expect("registered");
        assert_eq!(
            inflight.cancel("open", Some(TOKEN)),
            CancelVerdict::NotCancellable
        );
        assert_eq!(inflight.cancel("open", None), CancelVerdict::NotCancellable);
        assert!(!stop.load(Ordering::Relaxed));
        inflight.stop_all();
        assert!(stop.load(Ordering::Relaxed) && wake.is_cancelled());
    }

    #[test]
    fn an_id_in_flight_is_refused_until_it_ends() {
        let inflight = InFlight::default();
        inflight.register("same", None).expect("first");
        assert!(matches!(
            inflight.register("same", Some(TOKEN.into())),
            Err(AlreadyInFlight)
        ));
        inflight.remove("same");
        assert!(inflight.is_empty());
        inflight.register("same", None).expect("after it ended");
    }
}
