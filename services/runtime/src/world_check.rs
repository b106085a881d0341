//! A service's check that the world it was given is the map server's.
//!
//! The sim, localization, the controller and the mapper each load a scenario of their
//! own. [`crate::Service::guard_world`] asks the map server for its world
//! (`<root>/map/layers`) in the background until one answers; when its world differs,
//! the service stops, and its shutdown returns a [`WorldMismatch`] naming both worlds. Until a map server answers the service runs
//! (a fleet starts in any order), and a map server that does not know its world (an
//! old data dir) is not a mismatch.

use std::time::Duration;

use roam_proto::map::{LayerList, WorldId};
use tokio_util::sync::CancellationToken;

use crate::client::Requester;

/// How long one ask waits for the map server, and how long between asks.
pub(crate) const ASK_EVERY: Duration = Duration::from_secs(1);

/// A service was given another world than the map server's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the {service} was given world {mine}, but the map server holds world {map_server}: give every service of a stack the same map or scenario (roam stack --scenario, or the same --scenario/--map to each role)")]
pub struct WorldMismatch {
    pub service: &'static str,
    pub mine: WorldId,
    pub map_server: WorldId,
}

/// Asks the map server at `key` for its world until one answers (or `cancel`); the
/// mismatch when its world is not `mine`. A map server that does not say which world it
/// holds (an old data dir) is not a mismatch. [`crate::Service::guard_world`] runs it in
/// the background of a service.
pub(crate) async fn check(
    requester: &Requester,
    key: &str,
    service: &'static str,
    mine: WorldId,
    cancel: &CancellationToken,
) -> Option<WorldMismatch> {
    loop {
        let asked = tokio::select! {
            _ = cancel.cancelled() => return None,
            asked = requester.request::<LayerList, LayerList>(key, None) => asked,
        };
        if let Ok(list) = asked {
            return match list.world {
                Some(theirs) if theirs.hash != mine.hash => Some(WorldMismatch {
                    service,
                    mine,
                    map_server: theirs,
                }),
                Some(_) => {
                    tracing::debug!(service, "on the map server's world");
                    None
                }
                None => {
                    tracing::info!(
                        service,
                        "the map server does not say which world it holds; not checked"
                    );
                    None
                }
            };
        }
        tokio::select! {
            _ = cancel.cancelled() => return None,
            _ = tokio::time::sleep(ASK_EVERY) => {}
        }
    }
}
