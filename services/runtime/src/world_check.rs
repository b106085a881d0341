//! A service's check that the world it was given is the map server's.
//!
//! The sim, localization, the controller and the mapper each load a scenario of their
//! own. [`guard`] asks the map server for its world (`<root>/map/layers`) in the
//! background until one answers; when its world differs, the service stops with a
//! [`WorldMismatch`] naming both worlds. Until a map server answers the service runs
//! (a fleet starts in any order), and a map server that does not know its world (an
//! old data dir) is not a mismatch.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::{Requester, Service};
use roam_proto::keys;
use roam_proto::map::{LayerList, WorldId};

/// How long one ask waits for the map server, and how long between asks.
const ASK_EVERY: Duration = Duration::from_secs(1);

/// A service was given another world than the map server's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the {service} was given world {mine}, but the map server holds world {map_server}: give every service of a stack the same map or scenario (roam stack --scenario, or the same --scenario/--map to each role)")]
pub struct WorldMismatch {
    pub service: &'static str,
    pub mine: WorldId,
    pub map_server: WorldId,
}

/// What the background check found.
#[derive(Debug, Clone, Default)]
pub struct WorldGuard {
    mismatch: Arc<Mutex<Option<WorldMismatch>>>,
}

impl WorldGuard {
    /// `Err` when the map server's world turned out to be another.
    pub fn outcome(&self) -> Result<(), WorldMismatch> {
        match crate::lock(&self.mismatch).clone() {
            Some(mismatch) => Err(mismatch),
            None => Ok(()),
        }
    }
}

/// Starts the check for `service`, which works on world `mine`; a mismatch stops the
/// service (its `run` then returns [`WorldGuard::outcome`]'s error).
pub fn guard(service: &Service, mine: WorldId) -> WorldGuard {
    let guard = WorldGuard::default();
    let found = guard.mismatch.clone();
    let requester = Requester::new(service.session().clone(), ASK_EVERY);
    let key = keys::map_index(service.root());
    let (name, cancel) = (service.name(), service.cancel_token());
    service.spawn(async move {
        loop {
            let asked = tokio::select! {
                _ = cancel.cancelled() => return,
                asked = requester.request::<LayerList, LayerList>(&key, None) => asked,
            };
            if let Ok(list) = asked {
                match list.world {
                    Some(theirs) if theirs.hash != mine.hash => {
                        let mismatch = WorldMismatch {
                            service: name,
                            mine,
                            map_server: theirs,
                        };
                        tracing::error!("{mismatch}");
                        *crate::lock(&found) = Some(mismatch);
                        cancel.cancel();
                    }
                    Some(_) => tracing::debug!(service = name, "on the map server's world"),
                    None => tracing::info!(
                        service = name,
                        "the map server does not say which world it holds; not checked"
                    ),
                }
                return;
            }
            tokio::select! {
                _ = cancel.cancelled() => return,
                _ = tokio::time::sleep(ASK_EVERY) => {}
            }
        }
    });
    guard
}
