//! The map server through Zenoh: gets, updates, stale refusals, every error path,
//! deletes and a graceful stop here; loads from the configured directories in
//! `loads.rs`; restarts, corrupt files and kills between saves in `persistence.rs`.
//! Each test boots a real router and a real map server in process and talks to them
//! only as a Zenoh client.

mod loads;
mod persistence;

use std::time::Duration;

use roam_map_server::store::{Limits, DEFAULT_LIMITS};
use roam_map_server::MapServerConfig;
use roam_proto::cells::Cells;
use roam_proto::layer_delta::LayerDelta;
use roam_proto::map::{
    CellWrite, DeleteLayer, Layer, LayerChange, LayerDeleted, LayerList, LayerUpdate, LoadMap,
    UpdateAck,
};
use roam_proto::{encode, keys, ErrorCode, ErrorReply};
use roam_runtime::{ClientError, Requester};
use roam_tests::{repo_path, within, Harness};

async fn get_layer(client: &Requester, root: &str, name: &str) -> Layer {
    within(
        "layer get",
        client.request::<Layer, Layer>(&keys::map_layer(root, name), None),
    )
    .await
    .expect("layer")
}

fn set(base_version: u64, x: u32, y: u32, value: f64) -> LayerUpdate {
    LayerUpdate {
        base_version,
        change: LayerChange::SetCells {
            cells: vec![CellWrite { x, y, value }],
        },
        world: None,
    }
}

async fn refusal<T: roam_proto::Message + std::fmt::Debug>(
    outcome: impl std::future::Future<Output = Result<T, ClientError>>,
) -> ErrorReply {
    match within("refused request", outcome).await {
        Err(ClientError::Refused(reply)) => reply,
        other => panic!("expected a structured refusal, got {other:?}"),
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_client_gets_every_layer_of_the_builtin_world() {
    let harness = Harness::start().await;
    let server = harness.start_role(harness.map_server_config()).await;
    let client = harness.client().await;

    let occupancy = get_layer(&client, &harness.root, "occupancy").await;
    assert_eq!(
        (
            occupancy.meta.width,
            occupancy.meta.height,
            occupancy.version
        ),
        (100, 100, 1)
    );
    assert!(matches!(occupancy.cells, Cells::I8(_)));
    let heuristic = get_layer(&client, &harness.root, "heuristic").await;
    assert_eq!(
        (heuristic.meta.width, heuristic.meta.height),
        (4, 4),
        "c_h = 1/4"
    );

    let list: LayerList = within(
        "index",
        client.request::<LayerList, LayerList>(&keys::map_index(&harness.root), None),
    )
    .await
    .expect("list");
    let names: Vec<&str> = list.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["heuristic", "inflated", "information", "occupancy"]);

    // A wildcard get answers with every layer.
    let replies = within(
        "wildcard get",
        client.session().get(keys::map_layer_any(&harness.root)),
    )
    .await
    .expect("get");
    let mut count = 0;
    while let Ok(reply) = within("reply", replies.recv_async()).await {
        assert!(reply.result().is_ok());
        count += 1;
    }
    assert_eq!(count, 4);

    let missing =
        refusal(client.request::<Layer, Layer>(&keys::map_layer(&harness.root, "nope"), None))
            .await;
    assert_eq!(missing.code, ErrorCode::NotFound);
    assert!(
        missing.message.contains("occupancy"),
        "names what exists: {}",
        missing.message
    );

    let (_, outcome) = server.stop().await;
    outcome.expect("clean stop");
    harness.close().await;
}

/// A one-cell update is published as a delta of each changed layer (the cell written,
/// and the cells `inflated` gains), which turns a follower's copy at the base version
/// into the server's new version; nothing of the whole layer is published.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn an_update_is_published_as_a_delta_and_a_stale_one_refused() {
    let harness = Harness::start().await;
    let server = harness.start_role(harness.map_server_config()).await;
    let client = harness.client().await;
    let subscribe = |key: String| within("subscribe", client.session().declare_subscriber(key));
    let deltas = subscribe(keys::map_delta_any(&harness.root))
        .await
        .expect("subscriber");
    let wholes = subscribe(keys::map_layer_any(&harness.root))
        .await
        .expect("subscriber");
    let mut inflated = get_layer(&client, &harness.root, "inflated").await;
    let mut occupancy = get_layer(&client, &harness.root, "occupancy").await;

    let update_key = keys::map_update(&harness.root, "occupancy");
    let ack: UpdateAck = within(
        "update",
        client.request(&update_key, Some(&set(1, 50, 50, 100.0))),
    )
    .await
    .expect("ack");
    assert_eq!(ack.version, 2);
    assert_eq!(
        ack.derived
            .iter()
            .map(|d| (d.name.as_str(), d.version))
            .collect::<Vec<_>>(),
        [("inflated", 2)]
    );

    // Both deltas arrive, each from version 1 to 2, and apply to the copies held.
    for _ in 0..2 {
        let sample = within("delta", deltas.recv_async()).await.expect("sample");
        let delta: LayerDelta = roam_proto::decode(&sample.payload().to_bytes()).expect("delta");
        assert_eq!(
            sample.key_expr().as_str(),
            keys::map_delta(&harness.root, &delta.name)
        );
        assert_eq!((delta.base_version, delta.version), (1, 2));
        assert!(
            sample.payload().len() < 4096,
            "{} bytes",
            sample.payload().len()
        );
        let held = match delta.name.as_str() {
            "occupancy" => &mut occupancy,
            "inflated" => &mut inflated,
            other => panic!("a delta of {other}"),
        };
        delta.apply(held).expect("applies to version 1");
    }
    assert_eq!(
        inflated.cells.get_f64(50 * 100 + 51),
        Some(100.0),
        "inflated next to the new obstacle"
    );
    assert_eq!(
        inflated,
        get_layer(&client, &harness.root, "inflated").await
    );
    assert_eq!(
        occupancy,
        get_layer(&client, &harness.root, "occupancy").await
    );
    assert!(
        wholes.try_recv().ok().flatten().is_none(),
        "no whole layer is published for a one-cell update"
    );

    let occupancy = get_layer(&client, &harness.root, "occupancy").await;
    assert_eq!(
        (occupancy.version, occupancy.cells.get_f64(50 * 100 + 50)),
        (2, Some(100.0))
    );

    // A second writer that still holds version 1 is refused, and nothing changes.
    let stale = refusal(
        client.request::<LayerUpdate, UpdateAck>(&update_key, Some(&set(1, 10, 10, 100.0))),
    )
    .await;
    assert_eq!(stale.code, ErrorCode::StaleVersion);
    assert!(stale.message.contains("version 2"), "{}", stale.message);
    assert_eq!(
        get_layer(&client, &harness.root, "occupancy")
            .await
            .cells
            .get_f64(10 * 100 + 10),
        Some(0.0)
    );

    server.stop().await.1.expect("clean stop");
    harness.close().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn malformed_and_wrong_version_payloads_get_structured_errors() {
    let harness = Harness::start().await;
    let server = harness.start_role(harness.map_server_config()).await;
    let client = harness.client().await;
    let key = keys::map_update(&harness.root, "occupancy");

    let malformed =
        refusal(client.request_raw::<UpdateAck>(&key, Some(b"{not json".to_vec()))).await;
    assert_eq!(malformed.code, ErrorCode::Malformed);

    let mut value: serde_json::Value =
        serde_json::from_slice(&encode(&set(1, 0, 0, 0.0))).expect("json");
    value["v"] = 99.into();
    let wrong_version = refusal(
        client.request_raw::<UpdateAck>(&key, Some(serde_json::to_vec(&value).expect("json"))),
    )
    .await;
    assert_eq!(wrong_version.code, ErrorCode::UnsupportedVersion);
    assert!(
        wrong_version.message.contains("99"),
        "{}",
        wrong_version.message
    );

    let mut trailing = encode(&set(1, 0, 0, 0.0));
    trailing.extend_from_slice(b" garbage");
    assert_eq!(
        refusal(client.request_raw::<UpdateAck>(&key, Some(trailing)))
            .await
            .code,
        ErrorCode::Malformed
    );

    let wrong_kind = refusal(client.request::<LoadMap, UpdateAck>(
        &key,
        Some(&LoadMap {
            path: "x".into(),
            base_version: None,
        }),
    ))
    .await;
    assert_eq!(wrong_kind.code, ErrorCode::WrongMessage);

    let no_payload = refusal(client.request::<LayerUpdate, UpdateAck>(&key, None)).await;
    assert_eq!(no_payload.code, ErrorCode::Malformed);

    let derived = refusal(client.request::<LayerUpdate, UpdateAck>(
        &keys::map_update(&harness.root, "inflated"),
        Some(&set(1, 0, 0, 0.0)),
    ))
    .await;
    assert_eq!(derived.code, ErrorCode::InvalidRequest);

    let outside =
        refusal(client.request::<LayerUpdate, UpdateAck>(&key, Some(&set(1, 100, 0, 0.0)))).await;
    assert!(outside.message.contains("outside"), "{}", outside.message);

    server.stop().await.1.expect("clean stop");
    harness.close().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn oversize_updates_are_refused_naming_the_limit() {
    let harness = Harness::start().await;
    let config = roam_map_server::MapServerConfig {
        limits: Limits {
            max_cells_per_update: 10,
            max_request_bytes: 4096,
            ..DEFAULT_LIMITS
        },
        ..harness.map_server_config()
    };
    let server = harness.start_role(config).await;
    let client = harness.client().await;
    let key = keys::map_update(&harness.root, "occupancy");

    let many = LayerUpdate {
        base_version: 1,
        change: LayerChange::SetCells {
            cells: (0..11)
                .map(|x| CellWrite {
                    x,
                    y: 1,
                    value: 100.0,
                })
                .collect(),
        },
        world: None,
    };
    let reply = refusal(client.request::<LayerUpdate, UpdateAck>(&key, Some(&many))).await;
    assert_eq!(reply.code, ErrorCode::LimitExceeded);
    let limit = reply.limit.expect("limit named");
    assert_eq!(
        (limit.name.as_str(), limit.max, limit.actual),
        ("max_cells_per_update", 10, 11)
    );

    let huge = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta: roam_proto::map::GridMeta {
                width: 100,
                height: 100,
                resolution: 0.2,
                origin: Default::default(),
            },
            cells: Cells::F32(vec![0.0; 10_000]),
        },
        world: None,
    };
    let reply =
        refusal(client.request::<LayerUpdate, UpdateAck>(
            &keys::map_update(&harness.root, "peb"),
            Some(&huge),
        ))
        .await;
    assert_eq!(
        reply.limit.map(|l| l.name),
        Some("max_request_bytes".to_owned())
    );

    server.stop().await.1.expect("clean stop");
    harness.close().await;
}

/// Deleting a free layer through Zenoh: stale and protected deletions refused with a
/// structured error, then the layer gone from `get` and the list, and a layer created
/// again under its name going on from its version.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_free_layer_is_deleted_and_base_layers_are_refused() {
    let harness = Harness::start().await;
    let server = harness.start_role(harness.map_server_config()).await;
    let client = harness.client().await;
    let root = harness.root.as_str();
    let create = |base_version| LayerUpdate {
        base_version,
        change: LayerChange::Replace {
            meta: roam_proto::map::GridMeta {
                width: 4,
                height: 4,
                resolution: 0.5,
                origin: Default::default(),
            },
            cells: Cells::F32(vec![0.5; 16]),
        },
        world: None,
    };
    let ack: UpdateAck = within(
        "create",
        client.request(&keys::map_update(root, "scratch"), Some(&create(0))),
    )
    .await
    .expect("created");
    assert_eq!(ack.version, 1);
    let delete = |name: &str, base_version| {
        let key = keys::map_delete(root, name);
        let client = &client;
        async move {
            client
                .request::<DeleteLayer, LayerDeleted>(&key, Some(&DeleteLayer { base_version }))
                .await
        }
    };

    let stale = refusal(delete("scratch", 0)).await;
    assert_eq!(stale.code, ErrorCode::StaleVersion);
    assert!(stale.message.contains("at version 1"), "{}", stale.message);
    for base in ["occupancy", "inflated", "information", "heuristic"] {
        let refused = refusal(delete(base, 1)).await;
        assert_eq!(refused.code, ErrorCode::InvalidRequest, "{base}");
        assert!(
            refused.message.contains("cannot be deleted"),
            "{}",
            refused.message
        );
    }
    let wildcard = refusal(client.request::<DeleteLayer, LayerDeleted>(
        &keys::map_delete_any(root),
        Some(&DeleteLayer { base_version: 1 }),
    ))
    .await;
    assert_eq!(wildcard.code, ErrorCode::InvalidRequest);

    let deleted = within("delete", delete("scratch", 1))
        .await
        .expect("deleted");
    assert_eq!(
        deleted,
        LayerDeleted {
            layer: "scratch".into(),
            version: 1
        }
    );
    let gone =
        refusal(client.request::<Layer, Layer>(&keys::map_layer(root, "scratch"), None)).await;
    assert_eq!(gone.code, ErrorCode::NotFound);
    let list: LayerList = within(
        "index",
        client.request::<LayerList, LayerList>(&keys::map_index(root), None),
    )
    .await
    .expect("list");
    assert!(!list.layers.iter().any(|l| l.name == "scratch"), "{list:?}");
    let again = refusal(delete("scratch", 1)).await;
    assert_eq!(again.code, ErrorCode::NotFound);

    let ack: UpdateAck = within(
        "create again",
        client.request(&keys::map_update(root, "scratch"), Some(&create(0))),
    )
    .await
    .expect("created again");
    assert_eq!(ack.version, 2, "goes on from the deleted layer's version");

    server.stop().await.1.expect("clean stop");
    harness.close().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_service_stops_within_two_seconds_and_drops_its_token() {
    let harness = Harness::start().await;
    let server = harness.start_role(harness.map_server_config()).await;
    assert!(harness.is_live(roam_map_server::SERVICE_NAME).await);
    let (took, outcome) = server.stop().await;
    outcome.expect("clean stop");
    assert!(took < Duration::from_secs(2), "stopping took {took:?}");
    assert!(!harness.is_live(roam_map_server::SERVICE_NAME).await);
    harness.close().await;
}
