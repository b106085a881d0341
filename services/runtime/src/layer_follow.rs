//! Following the map server's layers from outside it, as the live view and the ROS 2
//! node do: each layer published on `<root>/map/layer/<name>`, each delta on
//! `<root>/map/delta/<name>` applied to the layer held when that is the delta's base
//! version, and at start and every [`REFRESH_PERIOD`] a look at `<root>/map/layers`,
//! fetching every layer whose version is not the one held (a follower started after the
//! map server, or one that missed a delta it could not apply, catches up).
//!
//! [`follow_layers`] is the loop; a [`LayerSink`] is what a follower does with a layer
//! (show it in Foxglove, publish it as a ROS grid), how it queries, what it keeps and
//! how it counts what it refused. The loop decides when to apply, ignore or fetch.

use std::fmt::Display;
use std::future::Future;
use std::time::Duration;

use roam_proto::excerpt::excerpt;
use roam_proto::keys;
use roam_proto::layer_delta::{LayerDelta, MAX_DELTA_BYTES};
use roam_proto::map::{Layer, LayerList};
use roam_proto::Message;
use tokio::time::MissedTickBehavior;
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;

use crate::LatestSamples;

/// How often a follower looks at the layer index.
pub const REFRESH_PERIOD: Duration = Duration::from_secs(5);

/// What a follower does with the layers [`follow_layers`] hands it.
pub trait LayerSink: Send {
    /// Why a query got no layer or no index.
    type Error: Display + Send;
    /// The largest layer sample read, bytes.
    const MAX_LAYER_BYTES: usize;
    /// The most layers of the index fetched at one refresh.
    const MAX_LAYERS: usize;

    /// Whether layer `name` is followed at all (the ROS node: the layers it has a
    /// topic for).
    fn follows(&self, name: &str) -> bool;
    /// The version held of layer `name`.
    fn held(&self, name: &str) -> Option<u64>;
    /// Takes the layer `name` kept for deltas out of the sink (`None` when none is kept):
    /// a delta is applied to it in place and the result shown, so a layer of tens of
    /// megabytes is not copied for every delta.
    fn take_kept(&mut self, name: &str) -> Option<Layer>;
    /// A layer to show: published (always news) or fetched (`published` false).
    fn show(&mut self, layer: Layer, published: bool) -> impl Future<Output = ()> + Send;
    /// Decodes a sample of at most `max` bytes, or counts and reports it.
    fn decode<T: Message>(&self, sample: &Sample, max: usize) -> Option<T>;
    /// A message not believed (named for another key, a name that is not a key
    /// segment), from `key`.
    fn refuse(&self, key: &str, reason: &str);
    /// A query that got no usable answer.
    fn unread(&self, key: &str, error: &Self::Error);
    /// Asks for the whole layer on `key`.
    fn query_layer(&self, key: &str) -> impl Future<Output = Result<Layer, Self::Error>> + Send;
    /// Asks for the layer index on `key`.
    fn query_index(&self, key: &str)
        -> impl Future<Output = Result<LayerList, Self::Error>> + Send;
    /// The rest of a refresh, after the layers (the view: the sim's status).
    fn refreshed(&mut self) -> impl Future<Output = ()> + Send {
        async {}
    }
}

/// What a delta does to the layer held.
#[derive(Debug, PartialEq)]
pub enum DeltaStep {
    /// The layer held is the delta's version or later (a delta that arrived late; a map
    /// server restarted with lower versions is caught up by the refresh): nothing.
    Stale,
    /// The delta applied to the layer held: the new version.
    Applied(Layer),
    /// The follower holds nothing of the layer, did not keep it, or missed a delta
    /// (the base is not the version held): fetch the layer whole.
    Fetch,
}

/// What `delta` does to a layer held at version `held`: `take_kept` hands over the layer
/// kept for deltas, and is called only when the delta is newer than what is held.
pub fn delta_step(
    held: Option<u64>,
    take_kept: impl FnOnce() -> Option<Layer>,
    delta: &LayerDelta,
) -> DeltaStep {
    let Some(version) = held else {
        return DeltaStep::Fetch;
    };
    if version >= delta.version {
        return DeltaStep::Stale;
    }
    let Some(mut layer) = take_kept() else {
        return DeltaStep::Fetch;
    };
    match delta.apply(&mut layer) {
        Ok(()) => DeltaStep::Applied(layer),
        Err(e) => {
            tracing::debug!(layer = %delta.name, "delta not applied, the layer is fetched: {e}");
            DeltaStep::Fetch
        }
    }
}

/// Follows the layers on `root` until `cancel` or a closed subscription, handing each
/// to `sink`.
pub async fn follow_layers<S: LayerSink>(
    sink: &mut S,
    root: &str,
    layers: LatestSamples,
    deltas: LatestSamples,
    cancel: CancellationToken,
) {
    let mut refresh = tokio::time::interval(REFRESH_PERIOD);
    refresh.set_missed_tick_behavior(MissedTickBehavior::Delay);
    loop {
        tokio::select! {
            biased;
            _ = cancel.cancelled() => break,
            sample = layers.recv_async() => match sample {
                Ok(sample) => {
                    tokio::select! {
                        _ = cancel.cancelled() => break,
                        _ = on_layer(sink, root, &sample) => {}
                    }
                }
                Err(_) => break,
            },
            sample = deltas.recv_async() => match sample {
                Ok(sample) => {
                    tokio::select! {
                        _ = cancel.cancelled() => break,
                        _ = on_delta(sink, root, &sample) => {}
                    }
                }
                Err(_) => break,
            },
            _ = refresh.tick() => {
                tokio::select! {
                    _ = cancel.cancelled() => break,
                    _ = refresh_layers(sink, root) => {}
                }
            }
        }
    }
}

async fn on_layer<S: LayerSink>(sink: &mut S, root: &str, sample: &Sample) {
    let Some(layer) = sink.decode::<Layer>(sample, S::MAX_LAYER_BYTES) else {
        return;
    };
    let key = sample.key_expr().as_str();
    if key != keys::map_layer(root, &layer.name) {
        let reason = format!("a layer named \"{}\" on another key", excerpt(&layer.name));
        return sink.refuse(key, &reason);
    }
    if sink.follows(&layer.name) {
        sink.show(layer, true).await;
    }
}

async fn on_delta<S: LayerSink>(sink: &mut S, root: &str, sample: &Sample) {
    let Some(delta) = sink.decode::<LayerDelta>(sample, MAX_DELTA_BYTES) else {
        return;
    };
    let key = sample.key_expr().as_str();
    if key != keys::map_delta(root, &delta.name) {
        let reason = format!("a delta of \"{}\" on another key", excerpt(&delta.name));
        return sink.refuse(key, &reason);
    }
    if !sink.follows(&delta.name) {
        return;
    }
    let held = sink.held(&delta.name);
    match delta_step(held, || sink.take_kept(&delta.name), &delta) {
        DeltaStep::Stale => {}
        DeltaStep::Applied(layer) => sink.show(layer, true).await,
        DeltaStep::Fetch => fetch(sink, root, &delta.name).await,
    }
}

/// Fetches layer `name` whole and hands it to the sink.
async fn fetch<S: LayerSink>(sink: &mut S, root: &str, name: &str) {
    // A name that is not a key segment would make a key of its own (a wildcard, say).
    if keys::check_name("layer", name).is_err() {
        let reason = format!("a layer named \"{}\" (not a key segment)", excerpt(name));
        return sink.refuse(&keys::map_index(root), &reason);
    }
    let key = keys::map_layer(root, name);
    match sink.query_layer(&key).await {
        Ok(layer) if layer.name == name => sink.show(layer, false).await,
        Ok(layer) => {
            let reason = format!("a layer named \"{}\" on another key", excerpt(&layer.name));
            sink.refuse(&key, &reason)
        }
        Err(e) => sink.unread(&key, &e),
    }
}

/// Fetches every layer followed whose version in the index is not the one held, then
/// does the rest of the sink's refresh.
async fn refresh_layers<S: LayerSink>(sink: &mut S, root: &str) {
    let index = keys::map_index(root);
    match sink.query_index(&index).await {
        Ok(list) => {
            let stale: Vec<String> = list
                .layers
                .iter()
                .filter(|info| sink.follows(&info.name))
                .take(S::MAX_LAYERS)
                .filter(|info| sink.held(&info.name) != Some(info.version))
                .map(|info| info.name.clone())
                .collect();
            for name in stale {
                fetch(sink, root, &name).await;
            }
        }
        Err(e) => tracing::debug!("no layer index yet: {e}"),
    }
    sink.refreshed().await;
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::cells::Cells;
    use roam_proto::layer_delta::CellPositions;
    use roam_proto::map::{GridMeta, Origin};

    fn layer(version: u64) -> Layer {
        Layer {
            name: "peb".into(),
            version,
            meta: GridMeta {
                width: 2,
                height: 1,
                resolution: 1.0,
                origin: Origin::default(),
            },
            derived_from: None,
            cells: Cells::F32(vec![0.0; 2]),
        }
    }

    fn delta(base_version: u64) -> LayerDelta {
        LayerDelta {
            name: "peb".into(),
            base_version,
            version: base_version + 1,
            positions: CellPositions(vec![(1, 0)]),
            values: Cells::F32(vec![7.0]),
        }
    }

    #[test]
    fn a_delta_at_the_version_held_applies() {
        let DeltaStep::Applied(after) = delta_step(Some(4), || Some(layer(4)), &delta(4)) else {
            panic!("a delta at its base applies");
        };
        assert_eq!(
            (after.version, after.cells),
            (5, Cells::F32(vec![0.0, 7.0]))
        );
    }

    #[test]
    fn a_late_delta_is_ignored_and_a_missed_one_fetches() {
        let untouched = || -> Option<Layer> { panic!("a stale delta takes nothing") };
        assert_eq!(delta_step(Some(6), untouched, &delta(4)), DeltaStep::Stale);
        assert_eq!(delta_step(Some(5), untouched, &delta(4)), DeltaStep::Stale);
        assert_eq!(
            delta_step(Some(3), || Some(layer(3)), &delta(4)),
            DeltaStep::Fetch
        );
    }

    #[test]
    fn a_layer_not_held_or_not_kept_is_fetched() {
        assert_eq!(delta_step(None, || None, &delta(4)), DeltaStep::Fetch);
        assert_eq!(delta_step(Some(4), || None, &delta(4)), DeltaStep::Fetch);
    }
}
