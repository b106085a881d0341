//! One stack, one world: `roam stack` on a Nav2 map runs every service on that map (and
//! leaves out those that need a sim world); a service given another world than the map
//! server's refuses it, naming both; the map server refuses an update made for another
//! world. All through Zenoh.

use std::time::Duration;

use roam_localization::service::LocalizationConfig;
use roam_proto::cells::Cells;
use roam_proto::map::{LayerChange, LayerList, LayerUpdate, UpdateAck, WorldId};
use roam_proto::{keys, ErrorCode};
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::{ClientError, Requester};
use roam_stack::stack::{Stack, StackOptions};
use roam_tests::{repo_path, within, Harness};
use tokio_util::sync::CancellationToken;

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_stack_on_a_nav2_map_runs_every_service_on_that_map() {
    let stack = within(
        "stack on depot.yaml",
        Stack::start(
            StackOptions {
                root: Some(format!("world-{}", std::process::id())),
                map: Some(repo_path("config/maps/depot.yaml")),
                planners: 1,
                ..StackOptions::default()
            },
            Duration::from_secs(30),
        ),
    )
    .await
    .expect("the stack starts on a map alone");
    let left_out: Vec<&str> = stack.left_out.iter().map(|(s, _)| *s).collect();
    assert_eq!(left_out, ["sim", "localization", "controller"]);
    let client = Requester::new(stack.router.session.clone(), Duration::from_secs(10));
    // The mapper's layers arrive once it has sent them (at its start).
    let until = std::time::Instant::now() + Duration::from_secs(20);
    let list = loop {
        let list: LayerList = within(
            "layers",
            client.request::<LayerList, LayerList>(&keys::map_index(&stack.root), None),
        )
        .await
        .expect("layers");
        if list.layers.iter().any(|l| l.name == "change_probability") {
            break list;
        }
        assert!(
            std::time::Instant::now() < until,
            "no mapper layers: {list:?}"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    let world = list.world.clone().expect("the map server names its world");
    assert_eq!(world.name, "depot");
    let occupancy = list
        .layers
        .iter()
        .find(|l| l.name == "occupancy")
        .expect("occupancy")
        .meta;
    for layer in &list.layers {
        if layer.name == "heuristic" {
            // Paper 000's block means: coarser cells over the same extent.
            let extent = |m: &roam_proto::map::GridMeta| {
                (
                    f64::from(m.width) * m.resolution,
                    f64::from(m.height) * m.resolution,
                )
            };
            let (hx, hy) = extent(&layer.meta);
            let (ox, oy) = extent(&occupancy);
            assert!(
                hx >= ox - 1e-9 && hy >= oy - 1e-9,
                "heuristic covers the map"
            );
            continue;
        }
        assert_eq!(
            (layer.meta.width, layer.meta.height),
            (occupancy.width, occupancy.height),
            "layer {} is not at the map's size",
            layer.name
        );
    }
    stack.shutdown().await.expect("clean stop");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_service_given_another_world_refuses_it_naming_both() {
    let harness = Harness::start().await;
    let server = harness.start_role(harness.map_server_config()).await;
    // Localization on ES1's world, beside a map server on the built-in one.
    let config = LocalizationConfig {
        service: ServiceConfig::at(harness.root.clone()),
        scenario: Some(repo_path("config/scenarios/es1.yaml")),
        ..LocalizationConfig::default()
    };
    let outcome = tokio::time::timeout(
        Duration::from_secs(20),
        roam_localization::service::run(config, harness.client_config(), CancellationToken::new()),
    )
    .await
    .expect("localization stops by itself on a world mismatch");
    let error = outcome.expect_err("refused").to_string();
    assert!(
        error.contains("downtime") && error.contains("es1") && error.contains("world"),
        "{error}"
    );

    // The map server refuses an update made for another world.
    let client = harness.client().await;
    let other = WorldId {
        name: "elsewhere".into(),
        hash: "0123456789abcdef".into(),
    };
    let list: LayerList = within(
        "layers",
        client.request::<LayerList, LayerList>(&keys::map_index(&harness.root), None),
    )
    .await
    .expect("layers");
    let meta = list
        .layers
        .iter()
        .find(|l| l.name == "occupancy")
        .expect("occupancy")
        .meta;
    let update = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta,
            cells: Cells::F32(vec![0.0; meta.cell_count() as usize]),
        },
        world: Some(other),
    };
    match within(
        "update for another world",
        client.request::<LayerUpdate, UpdateAck>(
            &keys::map_update(&harness.root, "peb"),
            Some(&update),
        ),
    )
    .await
    {
        Err(ClientError::Refused(reply)) => {
            assert_eq!(reply.code, ErrorCode::InvalidRequest);
            assert!(reply.message.contains("elsewhere"), "{}", reply.message);
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    server.stop().await.1.expect("clean stop");
    harness.close().await;
}
