//! The map server's memory across all layers: a stranger creating layer after layer is
//! refused once the layers would hold more than `max_total_cell_bytes`, with the limit
//! named, and the layers already held stay within it. (The per-layer and layer-count
//! limits alone let 64 maximal layers reach 4 GiB of cells.)

use roam_map_server::store::{Limits, DEFAULT_LIMITS};
use roam_map_server::MapServerConfig;
use roam_proto::cells::Cells;
use roam_proto::map::{
    DeleteLayer, GridMeta, LayerChange, LayerDeleted, LayerList, LayerUpdate, UpdateAck,
};
use roam_proto::{keys, ErrorCode};
use roam_runtime::{ClientError, Requester};
use roam_tests::{within, Harness};

/// The budget of this test's map server: the built-in world's layers (100 × 100: three
/// one-byte layers and a 4 × 4 f32 heuristic) and room for three 64 KiB layers.
const BASE_BYTES: u64 = 3 * 10_000 + 16 * 4;
const LAYER_BYTES: u64 = 128 * 128 * 4;
const BUDGET: u64 = BASE_BYTES + 3 * LAYER_BYTES;

fn stranger_layer() -> LayerUpdate {
    LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta: GridMeta {
                width: 128,
                height: 128,
                resolution: 0.1,
                origin: Default::default(),
            },
            cells: Cells::F32(vec![1.0; 128 * 128]),
        },
        world: None,
    }
}

/// Bytes of cells of every layer the map server lists.
async fn held(client: &Requester, root: &str) -> u64 {
    let list: LayerList = within(
        "layers",
        client.request::<LayerList, LayerList>(&keys::map_index(root), None),
    )
    .await
    .expect("layer list");
    list.layers
        .iter()
        .map(|l| l.meta.cell_count() * l.dtype.size() as u64)
        .sum()
}

pub(crate) async fn layers_within_the_budget(harness: &Harness, client: &Requester) {
    let server = harness
        .start_role(MapServerConfig {
            limits: Limits {
                max_total_cell_bytes: BUDGET,
                ..DEFAULT_LIMITS
            },
            ..harness.map_server_config()
        })
        .await;
    let root = &harness.root;
    assert_eq!(held(client, root).await, BASE_BYTES);
    let mut created = 0;
    let refused = loop {
        let key = keys::map_update(root, &format!("stranger{created}"));
        match within(
            "replace",
            client.request::<LayerUpdate, UpdateAck>(&key, Some(&stranger_layer())),
        )
        .await
        {
            Ok(_) => created += 1,
            Err(ClientError::Refused(reply)) => break reply,
            Err(e) => panic!("the map server did not answer: {e}"),
        }
        assert!(created <= 3, "layer {created} was taken over the budget");
    };
    assert_eq!(created, 3, "{}", refused.message);
    assert_eq!(refused.code, ErrorCode::LimitExceeded);
    let limit = refused.limit.expect("the limit is named");
    assert_eq!(
        (limit.name.as_str(), limit.max, limit.actual),
        ("max_total_cell_bytes", BUDGET, BUDGET + LAYER_BYTES)
    );
    assert!(
        refused.message.contains("max_total_cell_bytes"),
        "{}",
        refused.message
    );
    assert_eq!(held(client, root).await, BUDGET);

    // Deleting one makes room for one.
    let deleted: LayerDeleted = within(
        "delete",
        client.request(
            &keys::map_delete(root, "stranger0"),
            Some(&DeleteLayer { base_version: 1 }),
        ),
    )
    .await
    .expect("delete");
    assert_eq!(deleted.layer, "stranger0");
    let _: UpdateAck = within(
        "replace",
        client.request(
            &keys::map_update(root, "stranger3"),
            Some(&stranger_layer()),
        ),
    )
    .await
    .expect("room again after a deletion");
    assert_eq!(held(client, root).await, BUDGET);
    server.stop().await.1.expect("clean stop");
}
