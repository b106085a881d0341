//! What the view's integration tests share: a router on loopback with services around
//! it, and a plain WebSocket client speaking the Foxglove protocol as the Foxglove app
//! does. Each test binary uses some of it.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::future::IntoFuture;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use roam_map_server::MapServerConfig;
use roam_proto::keys;
use roam_proto::map::Layer;
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::{Requester, SessionArgs};
use roam_sim::service::SimConfig;
use roam_stack::{Role, Router};
use roam_view::{Access, ViewConfig, ViewHandle, ViewStats};
use serde_json::Value;
use tokio::task::JoinHandle;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::http::{HeaderName, HeaderValue};
use tokio_tungstenite::tungstenite::Message as WsMessage;
use tokio_util::sync::CancellationToken;

/// How long any single step may take before the test fails.
pub const STEP: Duration = Duration::from_secs(10);

/// The WebSocket subprotocol of the Foxglove SDK's server: the Foxglove WebSocket
/// protocol v1 under its current name (the protocol's messages are those of
/// `foxglove.websocket.v1`).
pub const SUBPROTOCOL: &str = "foxglove.sdk.v1";

pub async fn within<F: IntoFuture>(what: &str, future: F) -> F::Output {
    match tokio::time::timeout(STEP, future).await {
        Ok(value) => value,
        Err(_) => panic!("timed out after {STEP:?}: {what}"),
    }
}

static NEXT_ROOT: AtomicU32 = AtomicU32::new(0);

/// A router on a free loopback port (multicast off), a unique key root, and the services
/// started on it.
pub struct Stack {
    pub router: zenoh::Session,
    pub endpoint: String,
    pub root: String,
    pub cancel: CancellationToken,
    services: Vec<JoinHandle<Result<(), String>>>,
}

impl Stack {
    pub async fn start() -> Stack {
        let router = within("router", Router::on_loopback())
            .await
            .expect("router on loopback");
        Stack {
            router: router.session,
            endpoint: router.endpoint,
            root: format!(
                "view-test-{}-{}",
                std::process::id(),
                NEXT_ROOT.fetch_add(1, Ordering::Relaxed)
            ),
            cancel: CancellationToken::new(),
            services: Vec::new(),
        }
    }

    pub fn client_config(&self) -> zenoh::Config {
        SessionArgs::client_of(&self.endpoint)
            .zenoh_config(None)
            .expect("client config")
    }

    pub async fn client(&self) -> zenoh::Session {
        within("client", roam_runtime::session::open(self.client_config()))
            .await
            .expect("client session")
    }

    /// Waits until a liveliness token matching `key` exists.
    pub async fn wait_live(&self, key: String) {
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

    /// Starts a service of roam's role table and waits for its liveliness token.
    pub async fn start_role(&mut self, role: impl Into<Role>) {
        let role = role.into();
        let key = role.live_key();
        let run = role.run(self.client_config(), self.cancel.child_token());
        self.services.push(tokio::spawn(run));
        self.wait_live(key).await;
    }

    /// The map server on the built-in world.
    pub async fn start_map_server(&mut self) {
        let root = self.root.clone();
        self.start_role(MapServerConfig {
            service: ServiceConfig::at(root),
            ..MapServerConfig::default()
        })
        .await;
    }

    /// The sim on the built-in world, free-running at `rate` times real time.
    pub async fn start_sim(&mut self, rate: f64) {
        let root = self.root.clone();
        self.start_role(SimConfig {
            service: ServiceConfig::at(root),
            rate: Some(rate),
            ..SimConfig::default()
        })
        .await;
    }

    pub async fn occupancy(&self, requester: &Requester) -> Layer {
        within(
            "get occupancy",
            requester.request::<Layer, Layer>(&keys::map_layer(&self.root, "occupancy"), None),
        )
        .await
        .expect("occupancy")
    }

    pub async fn stop(self) {
        self.cancel.cancel();
        for service in self.services {
            let outcome = within("service stop", service).await.expect("join");
            outcome.expect("the service stopped cleanly");
        }
        let _ = within("router close", self.router.close()).await;
    }
}

/// The Foxglove WebSocket client's side of one connection.
pub struct FoxgloveClient {
    pub ws: tokio_tungstenite::WebSocketStream<
        tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>,
    >,
    pub server_info: Option<Value>,
    /// Advertised channels by topic.
    pub channels: BTreeMap<String, Value>,
}

impl FoxgloveClient {
    pub async fn connect(addr: SocketAddr) -> FoxgloveClient {
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
    pub async fn next(&mut self) -> Result<Vec<u8>, String> {
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
    pub async fn until_advertised(&mut self, topic: &str) -> Value {
        loop {
            if let Some(channel) = self.channels.get(topic) {
                return channel.clone();
            }
            let _ = self.next().await;
        }
    }

    pub async fn subscribe(&mut self, subscription: u32, channel: u64) {
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
    pub async fn next_message_data(&mut self) -> (u32, Vec<u8>) {
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

/// A WebSocket upgrade request to `url` offering `subprotocol`, with `headers` added.
pub fn upgrade(
    url: &str,
    subprotocol: &str,
    headers: &[(&str, &str)],
) -> tokio_tungstenite::tungstenite::handshake::client::Request {
    let mut request = url.into_client_request().expect("request");
    let fields = request.headers_mut();
    fields.insert(
        "sec-websocket-protocol",
        HeaderValue::from_str(subprotocol).expect("subprotocol"),
    );
    for (name, value) in headers {
        fields.insert(
            HeaderName::from_bytes(name.as_bytes()).expect("name"),
            HeaderValue::from_str(value).expect("value"),
        );
    }
    request
}

impl FoxgloveClient {
    /// Connects with `request`: the client, or the HTTP status of the refusal.
    pub async fn try_connect(
        request: tokio_tungstenite::tungstenite::handshake::client::Request,
    ) -> Result<(FoxgloveClient, String), u16> {
        match within(
            "WebSocket connect",
            tokio_tungstenite::connect_async(request),
        )
        .await
        {
            Ok((ws, response)) => {
                let chosen = response
                    .headers()
                    .get("sec-websocket-protocol")
                    .and_then(|v| v.to_str().ok())
                    .unwrap_or_default()
                    .to_owned();
                let client = FoxgloveClient {
                    ws,
                    server_info: None,
                    channels: BTreeMap::new(),
                };
                Ok((client, chosen))
            }
            Err(tokio_tungstenite::tungstenite::Error::Http(response)) => {
                Err(response.status().as_u16())
            }
            Err(e) => panic!("the connection failed without an HTTP answer: {e}"),
        }
    }

    /// Subscribes to `topic` (read until it is advertised) as subscription `id`.
    pub async fn subscribe_topic(&mut self, id: u32, topic: &str) {
        let channel = self.until_advertised(topic).await;
        let channel_id = channel["id"].as_u64().expect("channel id");
        self.subscribe(id, channel_id).await;
    }

    /// The `messageData` payloads that arrive within `quiet` of each other.
    pub async fn drain_message_data(&mut self, quiet: Duration) -> Vec<(u32, Vec<u8>)> {
        let mut all = Vec::new();
        while let Ok(data) = tokio::time::timeout(quiet, self.next_message_data()).await {
            all.push(data);
        }
        all
    }
}

/// A view on `session` for the stack's root, serving on a free loopback port.
pub async fn start_view(
    session: &zenoh::Session,
    root: &str,
    access: Access,
    mcap: Option<std::path::PathBuf>,
) -> (ViewHandle, CancellationToken) {
    let cancel = CancellationToken::new();
    let view = within(
        "view start",
        roam_view::run(
            session.clone(),
            ViewConfig {
                root: root.to_owned(),
                listen: Some("127.0.0.1:0".parse().expect("addr")),
                mcap,
                access,
            },
            cancel.clone(),
        ),
    )
    .await
    .expect("the view starts");
    (view, cancel)
}

/// Waits (polling) until the view's stats satisfy `done`; returns them.
pub async fn until_stats(
    view: &ViewHandle,
    what: &str,
    done: impl Fn(&ViewStats) -> bool,
) -> ViewStats {
    within(what, async {
        loop {
            let stats = view.stats();
            if done(&stats) {
                return stats;
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await
}

/// Everything `roam_view` logs in this test binary (debug and up, no colours), from
/// the first call on: installed once as the global subscriber.
pub fn captured_logs() -> std::sync::Arc<std::sync::Mutex<Vec<u8>>> {
    use std::sync::{Arc, Mutex, OnceLock};
    static LOGS: OnceLock<Arc<Mutex<Vec<u8>>>> = OnceLock::new();
    LOGS.get_or_init(|| {
        let logs: Arc<Mutex<Vec<u8>>> = Arc::default();
        let sink = logs.clone();
        let subscriber = tracing_subscriber::fmt()
            .with_env_filter(tracing_subscriber::EnvFilter::new("roam_view=debug"))
            .with_ansi(false)
            .with_writer(move || LogWriter(sink.clone()))
            .finish();
        tracing::subscriber::set_global_default(subscriber).expect("one global subscriber");
        logs
    })
    .clone()
}

struct LogWriter(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);

impl std::io::Write for LogWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let mut logs = roam_runtime::lock(&self.0);
        logs.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A mission for `robot` with `waypoints` waypoints.
pub fn mission(robot: &str, id: &str, waypoints: usize) -> roam_proto::controller::Mission {
    roam_proto::controller::Mission {
        after_step: None,
        robot: robot.into(),
        id: id.into(),
        waypoints: (0..waypoints).map(|i| [i as f64 * 0.5, 1.5]).collect(),
        recovery: false,
    }
}

/// Puts `payload` on `key`, blocking rather than dropping (large puts are fragmented and
/// would otherwise be lost whole).
pub async fn put(session: &zenoh::Session, key: String, payload: Vec<u8>) {
    within(
        "put",
        session
            .put(key, payload)
            .congestion_control(zenoh::qos::CongestionControl::Block),
    )
    .await
    .expect("put");
}
