//! The layers sent to the map server at most once per period, and the mapping moved to
//! the world the map server holds.

use std::sync::Arc;
use std::time::Duration;

use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::{
    GridMeta, Layer, LayerChange, LayerList, LayerUpdate, Origin, UpdateAck, OCCUPANCY_LAYER,
};
use roam_proto::mapper::{
    CHANGE_INFORMATION_LAYER, CHANGE_PROBABILITY_LAYER, CHANGE_RATE_LAYER, NEWS_LAYER,
    OCCUPIED_NOW_LAYER, RECENCY_LAYER,
};
use roam_runtime::Requester;
use roam_world::grid::Grid;
use tokio_util::sync::CancellationToken;

use crate::belief::occupied_now;

use super::shared::{MapperShared, Mapping};

/// The layers to send, with the world and grid they are of.
struct LayersToSend {
    world: roam_proto::map::WorldId,
    meta: GridMeta,
    layers: Vec<(&'static str, Cells)>,
}

/// The layers at the newest observation's time, if anything was observed (or a mission
/// heard) since they were last sent.
fn layers_to_send(state: &MapperShared) -> Option<LayersToSend> {
    let mut m = state.mapping();
    if !m.dirty {
        return None;
    }
    m.dirty = false;
    let now = m.now_s;
    let probability = m.map.probability_layer(now).cells;
    let scores = crate::change_map::scores(&probability);
    let mut layers = vec![
        (
            CHANGE_RATE_LAYER,
            Cells::F32(f32_cells(m.map.rate_layer().cells)),
        ),
        (CHANGE_PROBABILITY_LAYER, Cells::F32(f32_cells(probability))),
        (CHANGE_INFORMATION_LAYER, Cells::U8(scores)),
        (
            RECENCY_LAYER,
            Cells::F32(f32_cells(m.map.recency_layer(now).cells)),
        ),
    ];
    // Both are on the change map's grid by construction; an error would be a bug, logged
    // and that layer left out.
    match m.news.news_scores(&m.map, now, None) {
        Ok(news) => layers.push((NEWS_LAYER, Cells::U8(news.cells))),
        Err(e) => tracing::error!("no news layer: {e}"),
    }
    match occupied_now(&m.map, now, &state.belief, Some(&m.static_map)) {
        Ok(belief) => layers.push((OCCUPIED_NOW_LAYER, Cells::I8(belief.cells))),
        Err(e) => tracing::error!("no occupied_now layer: {e}"),
    }
    Some(LayersToSend {
        world: m.world.clone(),
        meta: m.meta,
        layers,
    })
}

/// Moves the mapping to the world the map server holds when it is another than the
/// mapping's (the map server took a map of another grid: `--ros2-map`, `map/load`):
/// what was learnt of the old world's cells means nothing on the new one, so the
/// mapping starts afresh on the new occupancy, and its layers go out on the new grid
/// for the new world. The map server has forgotten the old grid's layers by then.
async fn follow_world(state: &MapperShared, list: &LayerList, requester: &Requester) {
    let Some(theirs) = &list.world else {
        return;
    };
    if state.mapping().world.hash == theirs.hash {
        return;
    }
    let key = keys::map_layer(&state.root, OCCUPANCY_LAYER);
    let occupancy = match requester.request::<Layer, Layer>(&key, None).await {
        Ok(layer) => layer,
        Err(e) => return tracing::debug!("the new world's occupancy is not here yet: {e}"),
    };
    let Cells::I8(cells) = occupancy.cells else {
        return tracing::warn!("the map server's occupancy is not i8 cells; the mapping stays");
    };
    if cells.len() as u64 != occupancy.meta.cell_count() {
        return tracing::warn!("the map server's occupancy has the wrong cell count");
    }
    let static_map = Grid {
        meta: occupancy.meta,
        cells,
    };
    match state.spec.build(theirs.clone(), static_map) {
        Ok(fresh) => {
            let mut m = state.mapping();
            tracing::info!(
                world = %theirs,
                was = %m.world,
                "the map server holds another world: mapping it afresh on its {}x{} grid",
                occupancy.meta.width,
                occupancy.meta.height
            );
            let (epochs, now_s) = (m.epochs.clone(), m.now_s);
            *m = Mapping {
                epochs,
                now_s,
                ..fresh
            };
        }
        Err(e) => tracing::error!("cannot map the map server's new world: {e}"),
    }
}

/// Layers travel as f32 cells: the map server's float layer type, half the bytes.
fn f32_cells(cells: Vec<f64>) -> Vec<f32> {
    cells.into_iter().map(|v| v as f32).collect()
}

/// Sends the layers to the map server at most once per period.
pub(super) async fn publish_layers(
    state: Arc<MapperShared>,
    period: Duration,
    cancel: CancellationToken,
) {
    let requester = Requester::new(state.session.clone(), Duration::from_secs(5));
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(period) => {}
        }
        let list: LayerList = match requester
            .request::<LayerList, LayerList>(&keys::map_index(&state.root), None)
            .await
        {
            Ok(l) => l,
            Err(e) => {
                tracing::debug!("no map server to send the layers to: {e}");
                continue;
            }
        };
        follow_world(&state, &list, &requester).await;
        let Some(LayersToSend {
            world,
            meta,
            layers,
        }) = layers_to_send(&state)
        else {
            continue;
        };
        let meta = GridMeta {
            origin: Origin {
                yaw: 0.0,
                ..meta.origin
            },
            ..meta
        };
        let mut all_sent = true;
        for (name, cells) in layers {
            let base_version = list
                .layers
                .iter()
                .find(|l| l.name == name)
                .map_or(0, |l| l.version);
            let update = LayerUpdate {
                base_version,
                change: LayerChange::Replace { meta, cells },
                world: Some(world.clone()),
            };
            let sent = requester
                .request::<LayerUpdate, UpdateAck>(
                    &keys::map_update(&state.root, name),
                    Some(&update),
                )
                .await;
            if let Err(e) = sent {
                all_sent = false;
                tracing::warn!(layer = name, "the map server refused the layer: {e}");
            }
        }
        if all_sent {
            state.mapping().layers_sent += 1;
        } else {
            state.mapping().dirty = true;
        }
    }
}
