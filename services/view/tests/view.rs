//! The live view through Zenoh and a real WebSocket: a map server (and a sim) on
//! loopback around an in-process router, the view on its own session, a plain WebSocket
//! client speaking the Foxglove protocol as the Foxglove app does, and an MCAP recording
//! read back with the `mcap` crate.

mod common;

use std::collections::BTreeMap;
use std::time::Duration;

use common::{start_view, within, FoxgloveClient, Stack};
use foxglove::messages::{Grid, SceneUpdate};
use foxglove::Decode;
use roam_proto::cells::Cells;
use roam_proto::controller::Mission;
use roam_proto::map::{CellWrite, Layer, LayerChange, LayerUpdate, UpdateAck};
use roam_proto::{encode, keys};
use roam_runtime::Requester;
use roam_view::{Access, ViewConfig, ViewError};
use tokio_util::sync::CancellationToken;

fn occupancy_cells(layer: &Layer) -> &[i8] {
    match &layer.cells {
        Cells::I8(cells) => cells,
        other => panic!("occupancy is not i8: {other:?}"),
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_foxglove_client_sees_the_channels_and_receives_the_map() {
    let mut stack = Stack::start().await;
    stack.start_map_server().await;
    let requester = Requester::new(stack.client().await, Duration::from_secs(5));
    let occupancy = stack.occupancy(&requester).await;

    // The view on its own client session, a WebSocket server on a free port.
    let view_session = stack.client().await;
    let (view, cancel) = start_view(&view_session, &stack.root, Access::default(), None).await;
    let addr = view.websocket_addr().expect("listening");
    assert_ne!(addr.port(), 0);
    assert_eq!(view.websocket_url(), Some(format!("ws://{addr}")));

    let mut client = FoxgloveClient::connect(addr).await;
    let channel = client.until_advertised("/map/occupancy").await;
    let info = client.server_info.clone().expect("serverInfo comes first");
    assert_eq!(info["name"], "roam");
    assert_eq!(channel["schemaName"], "foxglove.Grid");
    assert_eq!(channel["encoding"], "protobuf");
    assert_eq!(channel["schemaEncoding"], "protobuf");
    for layer in ["inflated", "information", "heuristic"] {
        let channel = client.until_advertised(&format!("/map/{layer}")).await;
        assert_eq!(channel["schemaName"], "foxglove.Grid", "{layer}");
    }
    for topic in [
        roam_view::TRUTH_TOPIC,
        roam_view::ESTIMATE_TOPIC,
        roam_view::MISSION_TOPIC,
        roam_view::DRIVEN_TOPIC,
        roam_view::ANCHORS_TOPIC,
    ] {
        let channel = client.until_advertised(topic).await;
        assert_eq!(channel["schemaName"], "foxglove.SceneUpdate", "{topic}");
    }

    // The map was logged before this client subscribed: it gets the latched one.
    let channel_id = channel["id"].as_u64().expect("channel id");
    client.subscribe(7, channel_id).await;
    let (subscription, payload) = client.next_message_data().await;
    assert_eq!(subscription, 7);
    let grid = Grid::decode(payload.as_slice()).expect("a foxglove.Grid");
    let meta = occupancy.meta;
    assert_eq!(grid.frame_id, "map");
    assert_eq!(grid.column_count, meta.width);
    assert_eq!(grid.row_stride, meta.width);
    assert_eq!(grid.data.len() as u64, meta.cell_count());
    let pose = grid.pose.and_then(|p| p.position).expect("pose");
    assert_eq!((pose.x, pose.y), (meta.origin.x, meta.origin.y));
    let cells = occupancy_cells(&occupancy);
    let bytes: Vec<u8> = cells.iter().map(|&c| c as u8).collect();
    assert!(
        grid.data.as_ref() == bytes.as_slice(),
        "the grid holds the map's cells"
    );

    // A change to the map reaches the client live.
    let free = cells.iter().position(|&c| c == 0).expect("a free cell");
    let (x, y) = (free as u32 % meta.width, free as u32 / meta.width);
    let ack: UpdateAck = within(
        "map update",
        requester.request(
            &keys::map_update(&stack.root, "occupancy"),
            Some(&LayerUpdate {
                base_version: occupancy.version,
                change: LayerChange::SetCells {
                    cells: vec![CellWrite { x, y, value: 100.0 }],
                },
                world: None,
            }),
        ),
    )
    .await
    .expect("update accepted");
    assert_eq!(ack.version, occupancy.version + 1);
    let grid = loop {
        let (_, payload) = client.next_message_data().await;
        let grid = Grid::decode(payload.as_slice()).expect("a foxglove.Grid");
        if grid.data[free] == 100 {
            break grid;
        }
    };
    assert_eq!(grid.data.len() as u64, meta.cell_count());

    cancel.cancel();
    let stats = within("view stop", view.join())
        .await
        .expect("a clean stop");
    assert!(stats.logged >= 5, "{stats:?}");
    assert_eq!(stats.dropped, 0);
    let _ = within("view session close", view_session.close()).await;
    let _ = within("requester close", requester.session().close()).await;
    stack.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn an_mcap_recording_of_a_short_run_holds_the_map_robots_and_anchors() {
    let mut stack = Stack::start().await;
    stack.start_map_server().await;
    stack.start_sim(20.0).await;
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("run.mcap");

    // On the router's own session, as `roam demo` runs it.
    let cancel = CancellationToken::new();
    let view = within(
        "view start",
        roam_view::run(
            stack.router.clone(),
            ViewConfig {
                root: stack.root.clone(),
                listen: None,
                mcap: Some(path.clone()),
                access: Access::default(),
            },
            cancel.clone(),
        ),
    )
    .await
    .expect("the view starts");
    assert_eq!(view.websocket_addr(), None);
    assert_eq!(view.mcap_path(), Some(path.as_path()));

    // A short run: a mission for the robot, some steps of the sim (its true positions),
    // a message that is not a roam message (dropped), then stop.
    let client = stack.client().await;
    let truth = within(
        "subscribe",
        client.declare_subscriber(keys::robot_truth(&stack.root, "robot")),
    )
    .await
    .expect("subscriber");
    let mission = Mission {
        after_step: None,
        robot: "robot".into(),
        id: "m1".into(),
        waypoints: vec![[-8.0, -8.0], [-6.0, -8.0]],
        recovery: false,
    };
    within(
        "put mission",
        client.put(keys::robot_mission(&stack.root, "robot"), encode(&mission)),
    )
    .await
    .expect("put");
    within(
        "put garbage",
        client.put(keys::robot_mission(&stack.root, "robot"), "not roam"),
    )
    .await
    .expect("put");
    // 50 steps: 1 s at 20x, ample for the view to have fetched the map and the anchors.
    for _ in 0..50 {
        within("a true position", truth.recv_async())
            .await
            .expect("sample");
    }
    cancel.cancel();
    let stats = within("view stop", view.join())
        .await
        .expect("a clean stop");
    assert_eq!(stats.dropped, 1, "{stats:?}");

    let bytes = std::fs::read(&path).expect("the recording");
    let summary = mcap::Summary::read(&bytes)
        .expect("a readable MCAP")
        .expect("a finished MCAP has a summary");
    let topics: Vec<&str> = summary
        .channels
        .values()
        .map(|c| c.topic.as_str())
        .collect();
    for topic in [
        "/map/occupancy",
        "/robots/truth",
        "/anchors",
        "/robots/mission",
    ] {
        assert!(topics.contains(&topic), "{topic} missing from {topics:?}");
    }
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let mut occupancy_grid = None;
    let mut anchors = None;
    for message in mcap::MessageStream::new(&bytes).expect("messages") {
        let message = message.expect("a message");
        let topic = message.channel.topic.clone();
        *counts.entry(topic.clone()).or_default() += 1;
        match topic.as_str() {
            "/map/occupancy" => {
                let schema = message.channel.schema.as_ref().expect("schema");
                assert_eq!(schema.name, "foxglove.Grid");
                assert_eq!(message.channel.message_encoding, "protobuf");
                occupancy_grid = Some(Grid::decode(message.data.as_ref()).expect("grid"));
            }
            "/anchors" => {
                anchors = Some(SceneUpdate::decode(message.data.as_ref()).expect("scene"));
            }
            _ => {}
        }
    }
    assert!(counts.get("/map/occupancy") >= Some(&1), "{counts:?}");
    assert!(counts.get("/robots/truth") >= Some(&1), "{counts:?}");
    assert_eq!(counts.get("/robots/mission"), Some(&1), "{counts:?}");

    let requester = Requester::new(client.clone(), Duration::from_secs(5));
    let occupancy = stack.occupancy(&requester).await;
    let grid = occupancy_grid.expect("an occupancy grid");
    assert_eq!(grid.column_count, occupancy.meta.width);
    assert_eq!(grid.data.len() as u64, occupancy.meta.cell_count());

    // The built-in world's five anchors, each a cube.
    let anchors = anchors.expect("anchors");
    assert_eq!(anchors.entities[0].cubes.len(), 5);

    let _ = within("client close", client.close()).await;
    stack.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_view_needs_an_output_and_a_valid_root() {
    let stack = Stack::start().await;
    let refused = roam_view::run(
        stack.router.clone(),
        ViewConfig {
            root: stack.root.clone(),
            listen: None,
            mcap: None,
            access: Access::default(),
        },
        CancellationToken::new(),
    )
    .await;
    assert!(matches!(refused, Err(ViewError::NoOutput)), "{refused:?}");
    let refused = roam_view::run(
        stack.router.clone(),
        ViewConfig {
            root: "roam/**".into(),
            listen: Some("127.0.0.1:0".parse().expect("addr")),
            mcap: None,
            access: Access::default(),
        },
        CancellationToken::new(),
    )
    .await;
    assert!(matches!(refused, Err(ViewError::Root(_))), "{refused:?}");
    stack.stop().await;
}
