//! The live view through Zenoh and a real WebSocket: a map server (and a sim) on
//! loopback around an in-process router, the view on its own session, a plain WebSocket
//! client speaking the Foxglove protocol as the Foxglove app does, and an MCAP recording
//! read back with the `mcap` crate.

use std::collections::BTreeMap;
use std::future::IntoFuture;
use std::net::{SocketAddr, TcpListener};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Duration;

use foxglove::messages::{Grid, SceneUpdate};
use foxglove::Decode;
use futures_util::{SinkExt, StreamExt};
use roam_map_server::MapServerConfig;
use roam_proto::cells::Cells;
use roam_proto::controller::Mission;
use roam_proto::map::{CellWrite, Layer, LayerChange, LayerUpdate, UpdateAck};
use roam_proto::{encode, keys};
use roam_runtime::{Requester, SessionArgs};
use roam_sim::service::SimConfig;
use roam_view::{Access, ViewConfig, ViewError};
use serde_json::Value;
use tokio::task::JoinHandle;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::http::HeaderValue;
use tokio_tungstenite::tungstenite::Message as WsMessage;
use tokio_util::sync::CancellationToken;

/// How long any single step may take before the test fails.
const STEP: Duration = Duration::from_secs(10);

/// The WebSocket subprotocol of the Foxglove SDK's server: the Foxglove WebSocket
/// protocol v1 under its current name (the protocol's messages are those of
/// `foxglove.websocket.v1`).
const SUBPROTOCOL: &str = "foxglove.sdk.v1";

async fn within<F: IntoFuture>(what: &str, future: F) -> F::Output {
    match tokio::time::timeout(STEP, future).await {
        Ok(value) => value,
        Err(_) => panic!("timed out after {STEP:?}: {what}"),
    }
}

static NEXT_ROOT: AtomicU32 = AtomicU32::new(0);

/// A router on a free loopback port (multicast off), a unique key root, and the services
/// started on it.
struct Stack {
    router: zenoh::Session,
    endpoint: String,
    root: String,
    cancel: CancellationToken,
    services: Vec<JoinHandle<Result<(), String>>>,
}

impl Stack {
    async fn start() -> Stack {
        let mut last = None;
        for _ in 0..5 {
            let port = TcpListener::bind("127.0.0.1:0")
                .and_then(|l| l.local_addr())
                .expect("a free port")
                .port();
            let endpoint = format!("tcp/127.0.0.1:{port}");
            let config = SessionArgs::router_on(&endpoint)
                .zenoh_config(None)
                .expect("router config");
            match within("router", roam_runtime::session::open(config)).await {
                Ok(router) => {
                    return Stack {
                        router,
                        endpoint,
                        root: format!(
                            "view-test-{}-{}",
                            std::process::id(),
                            NEXT_ROOT.fetch_add(1, Ordering::Relaxed)
                        ),
                        cancel: CancellationToken::new(),
                        services: Vec::new(),
                    }
                }
                Err(e) => last = Some(e),
            }
        }
        panic!("no router: {last:?}");
    }

    fn client_config(&self) -> zenoh::Config {
        SessionArgs::client_of(&self.endpoint)
            .zenoh_config(None)
            .expect("client config")
    }

    async fn client(&self) -> zenoh::Session {
        within("client", roam_runtime::session::open(self.client_config()))
            .await
            .expect("client session")
    }

    /// Waits until a liveliness token matching `key` exists.
    async fn wait_live(&self, key: String) {
        let tokens = within(
            "liveliness subscriber",
            self.router
                .liveliness()
                .declare_subscriber(key)
                .history(true),
        )
        .await
        .expect("liveliness subscriber");
        within("a service's liveliness token", tokens.recv_async())
            .await
            .expect("token");
    }

    async fn start_map_server(&mut self) {
        let config = MapServerConfig {
            root: self.root.clone(),
            ..MapServerConfig::default()
        };
        let run = roam_map_server::run(config, self.client_config(), self.cancel.child_token());
        self.services.push(tokio::spawn(
            async move { run.await.map_err(|e| e.to_string()) },
        ));
        self.wait_live(keys::liveliness_of(
            &self.root,
            roam_map_server::SERVICE_NAME,
        ))
        .await;
    }

    /// The sim on the built-in world, free-running at `rate` times real time.
    async fn start_sim(&mut self, rate: f64) {
        let config = SimConfig {
            root: self.root.clone(),
            rate: Some(rate),
            ..SimConfig::default()
        };
        let run = roam_sim::service::run(config, self.client_config(), self.cancel.child_token());
        self.services.push(tokio::spawn(
            async move { run.await.map_err(|e| e.to_string()) },
        ));
        self.wait_live(keys::liveliness_of(
            &self.root,
            roam_sim::service::SERVICE_NAME,
        ))
        .await;
    }

    async fn occupancy(&self, requester: &Requester) -> Layer {
        within(
            "get occupancy",
            requester.request::<Layer, Layer>(&keys::map_layer(&self.root, "occupancy"), None),
        )
        .await
        .expect("occupancy")
    }

    async fn stop(self) {
        self.cancel.cancel();
        for service in self.services {
            let outcome = within("service stop", service).await.expect("join");
            outcome.expect("the service stopped cleanly");
        }
        let _ = within("router close", self.router.close()).await;
    }
}

fn occupancy_cells(layer: &Layer) -> &[i8] {
    match &layer.cells {
        Cells::I8(cells) => cells,
        other => panic!("occupancy is not i8: {other:?}"),
    }
}

/// The Foxglove WebSocket client's side of one connection.
struct FoxgloveClient {
    ws: tokio_tungstenite::WebSocketStream<
        tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>,
    >,
    server_info: Option<Value>,
    /// Advertised channels by topic.
    channels: BTreeMap<String, Value>,
}

impl FoxgloveClient {
    async fn connect(addr: SocketAddr) -> FoxgloveClient {
        let mut request = format!("ws://{addr}")
            .into_client_request()
            .expect("request");
        request.headers_mut().insert(
            "sec-websocket-protocol",
            HeaderValue::from_static(SUBPROTOCOL),
        );
        let (ws, response) = within(
            "WebSocket connect",
            tokio_tungstenite::connect_async(request),
        )
        .await
        .expect("the view accepts a Foxglove client");
        assert_eq!(
            response
                .headers()
                .get("sec-websocket-protocol")
                .map(|v| v.to_str().unwrap_or_default()),
            Some(SUBPROTOCOL)
        );
        FoxgloveClient {
            ws,
            server_info: None,
            channels: BTreeMap::new(),
        }
    }

    /// The next message: JSON ones (serverInfo, advertise, …) are recorded and returned as
    /// `Err(op)`; a binary one is returned as `Ok(bytes)`.
    async fn next(&mut self) -> Result<Vec<u8>, String> {
        loop {
            let message = within("a WebSocket message", self.ws.next())
                .await
                .expect("the connection stays open")
                .expect("a message");
            match message {
                WsMessage::Text(text) => {
                    let json: Value = serde_json::from_str(&text).expect("JSON");
                    let op = json["op"].as_str().unwrap_or_default().to_owned();
                    match op.as_str() {
                        "serverInfo" => self.server_info = Some(json),
                        "advertise" => {
                            for channel in json["channels"].as_array().expect("channels") {
                                let topic = channel["topic"].as_str().expect("topic").to_owned();
                                self.channels.insert(topic, channel.clone());
                            }
                        }
                        _ => {}
                    }
                    return Err(op);
                }
                WsMessage::Binary(bytes) => return Ok(bytes.to_vec()),
                _ => continue,
            }
        }
    }

    /// Reads until `topic` is advertised; returns its channel.
    async fn until_advertised(&mut self, topic: &str) -> Value {
        loop {
            if let Some(channel) = self.channels.get(topic) {
                return channel.clone();
            }
            let _ = self.next().await;
        }
    }

    async fn subscribe(&mut self, subscription: u32, channel: u64) {
        let request = serde_json::json!({
            "op": "subscribe",
            "subscriptions": [{"id": subscription, "channelId": channel}],
        });
        within(
            "subscribe",
            self.ws.send(WsMessage::Text(request.to_string().into())),
        )
        .await
        .expect("subscribe sent");
    }

    /// The next `messageData` (opcode 1): its subscription id and payload.
    async fn next_message_data(&mut self) -> (u32, Vec<u8>) {
        loop {
            if let Ok(bytes) = self.next().await {
                // opcode (1), subscription id (u32 LE), log time (u64 LE), payload
                assert!(bytes.len() >= 13, "a short binary message");
                if bytes[0] == 1 {
                    let id = u32::from_le_bytes([bytes[1], bytes[2], bytes[3], bytes[4]]);
                    return (id, bytes[13..].to_vec());
                }
            }
        }
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
    let cancel = CancellationToken::new();
    let view = within(
        "view start",
        roam_view::run(
            view_session.clone(),
            ViewConfig {
                root: stack.root.clone(),
                listen: Some("127.0.0.1:0".parse().expect("addr")),
                mcap: None,
                access: Access::default(),
            },
            cancel.clone(),
        ),
    )
    .await
    .expect("the view starts");
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
        robot: "robot".into(),
        id: "m1".into(),
        waypoints: vec![[-8.0, -8.0], [-6.0, -8.0]],
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
