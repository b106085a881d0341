//! The executive's follower of what the fleet believes occupied now
//! ([`ExecutiveConfig::obstacles_layer`], the mapper's `occupied_now`): the layer and
//! its deltas followed as the view and the ROS 2 node follow layers
//! (`roam_runtime::layer_follow`), the static `inflated` layer fetched beside it, and
//! every change of the believed obstacles (cells occupied now where the static map is
//! free) handed to the window loop as a [`SeenObstacles`] set, which checks the route
//! ahead against it (`window/blocked.rs`).
//!
//! Only the obstacle layer is subscribed to; `inflated` (which changes only when the map
//! is edited) is fetched at start and at each refresh of the map index
//! ([`roam_runtime::layer_follow::REFRESH_PERIOD`]) when its version moved.
//!
//! [`ExecutiveConfig::obstacles_layer`]: crate::config::ExecutiveConfig::obstacles_layer

use std::sync::Arc;
use std::time::Duration;

use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::{Layer, LayerList, INFLATED_LAYER as INFLATED};
use roam_proto::{decode, Message};
use roam_runtime::layer_follow::{follow_layers, LayerSink};
use roam_runtime::{subscribe_latest, ClientError, Requester};
use roam_world::grid::Grid;
use tokio::sync::watch;
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;

use crate::error::ExecutiveError;
use crate::seen::SeenObstacles;

/// The largest layer read: the map server's largest.
const MAX_LAYER_BYTES: usize = roam_runtime::service::DEFAULT_MAX_SAMPLE_BYTES;
/// How long one of its queries may take.
const QUERY_TIMEOUT: Duration = Duration::from_secs(5);

/// The believed obstacles, newest first: `None` until both layers are in.
pub(crate) type ObstacleSets = watch::Receiver<Option<Arc<SeenObstacles>>>;

/// Starts following `layer` under `root`; the sets arrive on the receiver. The
/// subscriptions are declared before this returns, so nothing published after is
/// missed.
pub(crate) async fn follow(
    session: &zenoh::Session,
    root: &str,
    layer: &str,
    clearance_m: f64,
    cancel: CancellationToken,
) -> Result<ObstacleSets, ExecutiveError> {
    let subscribe = |key: String| async move {
        subscribe_latest(session, &key, 4)
            .await
            .map_err(|e| ExecutiveError::Zenoh(format!("subscribing to {key}: {e}")))
    };
    let layers = subscribe(keys::map_layer(root, layer)).await?;
    let deltas = subscribe(keys::map_delta(root, layer)).await?;
    let (sets, receiver) = watch::channel(None);
    let mut sink = ObstacleSink {
        obstacles_layer: layer.to_owned(),
        clearance_m,
        requester: Requester::new(session.clone(), QUERY_TIMEOUT),
        seen: None,
        inflated: None,
        sets,
    };
    let root = root.to_owned();
    tokio::spawn(async move { follow_layers(&mut sink, &root, layers, deltas, cancel).await });
    Ok(receiver)
}

struct ObstacleSink {
    obstacles_layer: String,
    clearance_m: f64,
    requester: Requester,
    /// The obstacle layer as last shown: its deltas apply to it.
    seen: Option<Layer>,
    /// The static map's version and cells. Not kept as a layer for deltas: it changes
    /// only when the map is edited, and then the follower fetches it whole.
    inflated: Option<(u64, Grid<i8>)>,
    sets: watch::Sender<Option<Arc<SeenObstacles>>>,
}

impl ObstacleSink {
    /// The set the two layers held make, sent when it differs from the last one.
    fn send_if_changed(&self) {
        let (Some((_, grid)), Some(seen)) = (&self.inflated, &self.seen) else {
            return;
        };
        let Some(set) = SeenObstacles::of_layers(grid, seen, self.clearance_m) else {
            tracing::warn!(
                layer = %self.obstacles_layer,
                "the obstacle layer is not i8 cells on the inflated map's grid: routes are not checked"
            );
            return;
        };
        self.sets.send_if_modified(|last| {
            let changed = last.as_deref() != Some(&set);
            if changed {
                tracing::debug!(obstacles = set.points.len(), "believed obstacles changed");
                *last = Some(Arc::new(set));
            }
            changed
        });
    }
}

impl LayerSink for ObstacleSink {
    type Error = ClientError;
    const MAX_LAYER_BYTES: usize = MAX_LAYER_BYTES;
    const MAX_LAYERS: usize = 2;

    fn follows(&self, name: &str) -> bool {
        name == INFLATED || name == self.obstacles_layer
    }

    fn held(&self, name: &str) -> Option<u64> {
        if name == INFLATED {
            self.inflated.as_ref().map(|(version, _)| *version)
        } else {
            self.seen.as_ref().map(|l| l.version)
        }
    }

    fn take_kept(&mut self, name: &str) -> Option<Layer> {
        if name == INFLATED {
            None
        } else {
            self.seen.take()
        }
    }

    async fn show(&mut self, layer: Layer, _published: bool) {
        if layer.name == INFLATED {
            self.inflated = match layer.cells {
                Cells::I8(cells) => Some((
                    layer.version,
                    Grid {
                        meta: layer.meta,
                        cells,
                    },
                )),
                _ => None,
            };
        } else {
            self.seen = Some(layer);
        }
        self.send_if_changed();
    }

    fn decode<T: Message>(&self, sample: &Sample, max: usize) -> Option<T> {
        let key = sample.key_expr().as_str();
        let bytes = sample.payload().len();
        if bytes > max {
            tracing::warn!(%key, bytes, max, "a layer sample too large to read");
            return None;
        }
        decode::<T>(&sample.payload().to_bytes())
            .inspect_err(|e| tracing::warn!(%key, "a layer sample not read: {e}"))
            .ok()
    }

    fn refuse(&self, key: &str, reason: &str) {
        tracing::warn!(%key, "not believed: {reason}");
    }

    fn unread(&self, key: &str, error: &ClientError) {
        tracing::debug!(%key, "layer not fetched: {error}");
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
