//! The layers a planner plans on: followed as they are published, deltas applied to the
//! version held, and fetched whole at start and when a delta does not apply.

use std::sync::Arc;
use std::time::Duration;

use roam_proto::excerpt;
use roam_proto::keys;
use roam_proto::layer_delta::LayerDelta;
use roam_proto::map::Layer;
use roam_runtime::Requester;
use tokio_util::sync::CancellationToken;

use crate::maps::DeltaOutcome;

use super::instance::PlannerInstance;

pub(super) fn take_layer(state: &PlannerInstance, layer: Layer) {
    if let Some(version) = state.maps().update(layer) {
        tracing::info!(
            inflated = version.inflated,
            information = version.information,
            "planning on a new map"
        );
    }
}

/// A delta of a followed layer: applied, or (when it does not apply to the version
/// held) the whole layer is asked for.
pub(super) fn take_delta(state: &PlannerInstance, delta: &LayerDelta) {
    match state.maps().apply_delta(delta) {
        DeltaOutcome::Applied(Some(version)) => tracing::info!(
            inflated = version.inflated,
            information = version.information,
            "planning on a new map"
        ),
        DeltaOutcome::Gap(why) => {
            tracing::debug!(layer = %excerpt(&delta.name), "getting the whole layer: {why}");
            roam_runtime::lock(&state.wanted).insert(delta.name.clone());
            state.want.notify_one();
        }
        DeltaOutcome::Applied(None) | DeltaOutcome::Held | DeltaOutcome::NotFollowed => {}
    }
}

/// Gets each layer a delta could not be applied to, whole.
pub(super) async fn fetch_wanted(
    state: Arc<PlannerInstance>,
    requester: Requester,
    cancel: CancellationToken,
) {
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = state.want.notified() => {}
        }
        let wanted = std::mem::take(&mut *roam_runtime::lock(&state.wanted));
        for name in wanted {
            match requester
                .request::<Layer, Layer>(&keys::map_layer(&state.root, &name), None)
                .await
            {
                Ok(layer) if layer.name == name => take_layer(&state, layer),
                Ok(_) => {
                    tracing::warn!(layer = %name, "the map server answered with another layer")
                }
                Err(e) => tracing::debug!("map layer {name} not fetched: {e}"),
            }
        }
    }
}

/// Gets the two layers from the map server, retrying until both arrive.
pub(super) async fn fetch_maps(
    state: Arc<PlannerInstance>,
    requester: Requester,
    cancel: CancellationToken,
) {
    loop {
        let layers = state.maps().layers();
        for name in &layers {
            match requester
                .request::<Layer, Layer>(&keys::map_layer(&state.root, name), None)
                .await
            {
                Ok(layer) => take_layer(&state, layer),
                Err(e) => tracing::debug!("map layer {name} not available yet: {e}"),
            }
        }
        if state.maps().world(None).is_some() {
            return;
        }
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(Duration::from_millis(500)) => {}
        }
    }
}
