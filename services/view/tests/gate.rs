//! Who may connect to the live view, through a real WebSocket: the view on loopback, a
//! mission put through Zenoh, and a WebSocket client (tokio-tungstenite) whose upgrade
//! headers are set by hand, as a browser page, the Foxglove app or a stranger would send
//! them.

mod common;

use std::net::SocketAddr;
use std::time::Duration;

use common::{start_view, until_stats, upgrade, within, FoxgloveClient, Stack, SUBPROTOCOL};
use foxglove::messages::SceneUpdate;
use foxglove::Decode;
use roam_proto::controller::Mission;
use roam_proto::{encode, keys};
use roam_view::{Access, Token, ViewConfig, ViewError, ViewHandle, MISSION_TOPIC};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;
use tokio_util::sync::CancellationToken;

const TOKEN: &str = "5f0c1d2e3b4a69788796a5b4c3d2e1f0";
const APP: &str = "https://app.foxglove.dev";

/// A stack, a view with `access` on it, and a mission for robot `r1` that the view has
/// drawn: the data an admitted client must receive.
async fn view_with_a_mission(access: Access) -> (Stack, ViewHandle, CancellationToken, String) {
    let stack = Stack::start().await;
    let (view, cancel) = start_view(&stack.router, &stack.root, access, None).await;
    let client = stack.client().await;
    let mission = Mission {
        after_step: None,
        robot: "r1".into(),
        id: "m-gate".into(),
        waypoints: vec![[0.0, 0.0], [1.0, 2.0]],
        recovery: false,
    };
    within(
        "put mission",
        client.put(keys::robot_mission(&stack.root, "r1"), encode(&mission)),
    )
    .await
    .expect("put");
    until_stats(&view, "the mission drawn", |s| s.robots == 1).await;
    let _ = within("client close", client.close()).await;
    let url = format!("ws://{}", view.websocket_addr().expect("listening"));
    (stack, view, cancel, url)
}

/// Subscribes to the missions and checks that r1's arrives (latched, sent on subscribe).
async fn receives_the_mission(client: &mut FoxgloveClient) {
    client.subscribe_topic(3, MISSION_TOPIC).await;
    let (subscription, payload) = client.next_message_data().await;
    assert_eq!(subscription, 3);
    let update = SceneUpdate::decode(payload.as_slice()).expect("a SceneUpdate");
    assert_eq!(update.entities[0].id, "mission/r1");
}

async fn stop(stack: Stack, view: ViewHandle, cancel: CancellationToken) {
    cancel.cancel();
    within("view stop", view.join())
        .await
        .expect("a clean stop");
    stack.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_foreign_origin_is_forbidden_and_the_foxglove_app_receives_data() {
    let logs = common::captured_logs();
    let (stack, view, cancel, url) = view_with_a_mission(Access::default()).await;

    for origin in ["https://evil.example", "null", "http://app.foxglove.dev"] {
        let refused =
            FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[("Origin", origin)]));
        assert_eq!(refused.await.err(), Some(403), "{origin}");
    }
    // A long Origin is refused, and logged as one short, escaped line.
    let long = format!("https://{}.example", "a".repeat(6000));
    let refused = FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[("Origin", &long)]));
    assert_eq!(refused.await.err(), Some(403));

    // The Foxglove web app, and a native client that sends no Origin, connect and get data.
    let (mut app, chosen) =
        FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[("Origin", APP)]))
            .await
            .expect("the Foxglove app connects");
    assert_eq!(chosen, SUBPROTOCOL);
    receives_the_mission(&mut app).await;
    let (mut native, _) = FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[]))
        .await
        .expect("a client without an Origin connects");
    receives_the_mission(&mut native).await;

    let text = String::from_utf8_lossy(&logs.lock().expect("logs")).into_owned();
    let refusals: Vec<&str> = text
        .lines()
        .filter(|l| l.contains("refused a WebSocket client: 403"))
        .collect();
    assert!(refusals.len() >= 4, "{text}");
    assert!(
        refusals.iter().any(|l| l.contains("evil.example")),
        "{text}"
    );
    let long_line = refusals
        .iter()
        .find(|l| l.contains("aaaa"))
        .expect("the long Origin's line");
    assert!(long_line.len() < 400, "{} bytes", long_line.len());
    assert!(long_line.contains("bytes)"), "{long_line}");
    stop(stack, view, cancel).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn an_allow_list_replaces_the_default() {
    let access = Access::new(["http://localhost:3000"], None).expect("access");
    let (stack, view, cancel, url) = view_with_a_mission(access).await;
    let app = FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[("Origin", APP)]));
    assert_eq!(app.await.err(), Some(403));
    let (mut local, _) = FoxgloveClient::try_connect(upgrade(
        &url,
        SUBPROTOCOL,
        &[("Origin", "http://localhost:3000")],
    ))
    .await
    .expect("the listed origin connects");
    receives_the_mission(&mut local).await;
    stop(stack, view, cancel).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_wrong_or_missing_token_is_unauthorized_and_the_right_one_receives_data() {
    let token = Token::new(TOKEN).expect("token");
    let access = Access::new([APP], Some(token)).expect("access");
    let (stack, view, cancel, url) = view_with_a_mission(access).await;
    assert_eq!(
        view.websocket_url(),
        Some(format!("{url}/?token=<token>")),
        "the URL to give says a token is needed, without printing it"
    );

    let wrong = format!("{url}/?token={}", TOKEN.replace('5', "6"));
    for (target, headers) in [
        (url.clone(), vec![]),
        (wrong, vec![]),
        (
            url.clone(),
            vec![("Authorization", "Bearer 0000000000000000000000")],
        ),
        (url.clone(), vec![("Authorization", TOKEN)]),
    ] {
        let refused = FoxgloveClient::try_connect(upgrade(&target, SUBPROTOCOL, &headers));
        assert_eq!(refused.await.err(), Some(401), "{target} {headers:?}");
    }
    // The right token from a foreign page is still refused for its origin.
    let foreign = FoxgloveClient::try_connect(upgrade(
        &format!("{url}/?token={TOKEN}"),
        SUBPROTOCOL,
        &[("Origin", "https://evil.example")],
    ));
    assert_eq!(foreign.await.err(), Some(403));

    // In the URL, as the Foxglove app passes it, and as a bearer header.
    let (mut app, _) = FoxgloveClient::try_connect(upgrade(
        &format!("{url}/?token={TOKEN}"),
        SUBPROTOCOL,
        &[("Origin", APP)],
    ))
    .await
    .expect("the right token in the URL connects");
    receives_the_mission(&mut app).await;
    let bearer = format!("Bearer {TOKEN}");
    let (mut script, _) =
        FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[("Authorization", &bearer)]))
            .await
            .expect("the right bearer token connects");
    receives_the_mission(&mut script).await;
    stop(stack, view, cancel).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_client_offering_only_foxglove_websocket_v1_is_served() {
    let (stack, view, cancel, url) = view_with_a_mission(Access::default()).await;
    let (mut legacy, chosen) =
        FoxgloveClient::try_connect(upgrade(&url, "foxglove.websocket.v1", &[("Origin", APP)]))
            .await
            .expect("a foxglove.websocket.v1 client connects");
    assert_eq!(chosen, "foxglove.websocket.v1");
    receives_the_mission(&mut legacy).await;
    let info = legacy.server_info.clone().expect("serverInfo");
    assert_eq!(info["name"], "roam");
    // The schema is inline, as foxglove.websocket.v1 has it.
    let channel = legacy.until_advertised(MISSION_TOPIC).await;
    assert_eq!(channel["schemaName"], "foxglove.SceneUpdate");
    assert!(channel["schema"].as_str().is_some_and(|s| !s.is_empty()));

    // Offering both names: the SDK's is chosen, untouched.
    let both = "foxglove.websocket.v1, foxglove.sdk.v1";
    let (_, chosen) = FoxgloveClient::try_connect(upgrade(&url, both, &[]))
        .await
        .expect("connects");
    assert_eq!(chosen, SUBPROTOCOL);
    // Offering neither: the SDK's own refusal, through the gate.
    let other = FoxgloveClient::try_connect(upgrade(&url, "other.v1", &[]));
    assert_eq!(other.await.err(), Some(400));
    stop(stack, view, cancel).await;
}

/// Sends `bytes` on a raw connection and returns the status of the answer (0 if none).
async fn raw_status(addr: SocketAddr, bytes: &[u8]) -> u16 {
    let mut stream = within("connect", TcpStream::connect(addr))
        .await
        .expect("connect");
    let _ = stream.write_all(bytes).await;
    let mut answer = Vec::new();
    let _ = within("an answer", stream.read_to_end(&mut answer)).await;
    let text = String::from_utf8_lossy(&answer);
    text.strip_prefix("HTTP/1.1 ")
        .and_then(|t| t.get(..3))
        .and_then(|code| code.parse().ok())
        .unwrap_or(0)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn malformed_oversized_and_silent_clients_are_refused_within_bounds() {
    let stack = Stack::start().await;
    let (view, cancel) = start_view(&stack.router, &stack.root, Access::default(), None).await;
    let addr = view.websocket_addr().expect("listening");

    let smuggled = b"GET / HTTP/1.1\r\nOrigin: https://x\x1b[31m\r\n\r\n";
    assert_eq!(raw_status(addr, smuggled).await, 400);
    let folded = b"GET / HTTP/1.1\r\nX: 1\r\n Origin: https://app.foxglove.dev\r\n\r\n";
    assert_eq!(raw_status(addr, folded).await, 400);
    let mut endless = b"GET / HTTP/1.1\r\nX: ".to_vec();
    endless.extend(std::iter::repeat_n(b'a', 64 * 1024));
    assert_eq!(raw_status(addr, &endless).await, 431);

    // Slowloris: more connections than the half-open places, each sending half a head
    // and then nothing. The oldest are dropped (503) as newcomers arrive, a real client
    // still gets its upgrade at once, and the rest are answered when their time is up.
    let half = b"GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\n";
    let mut silent = Vec::new();
    for _ in 0..roam_view::MAX_HALF_OPEN + 8 {
        let mut stream = TcpStream::connect(addr).await.expect("connect");
        stream.write_all(half).await.expect("half a head");
        silent.push(stream);
    }
    tokio::time::sleep(Duration::from_millis(200)).await;
    let mut oldest = silent.remove(0);
    let mut answer = Vec::new();
    within("the evicted one's answer", oldest.read_to_end(&mut answer))
        .await
        .expect("read");
    assert!(answer.starts_with(b"HTTP/1.1 503 "), "{answer:?}");
    let client = FoxgloveClient::connect(addr).await;
    drop(client);
    let mut last = silent.pop().expect("a silent one");
    let mut answer = Vec::new();
    let waited = tokio::time::Instant::now();
    within("the head timeout", last.read_to_end(&mut answer))
        .await
        .expect("read");
    assert!(answer.starts_with(b"HTTP/1.1 408 "), "{answer:?}");
    assert!(waited.elapsed() <= roam_view::HEAD_TIMEOUT + Duration::from_secs(1));
    drop(silent);
    stop(stack, view, cancel).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_view_open_to_the_network_needs_a_token() {
    let stack = Stack::start().await;
    let config = |access: Access| ViewConfig {
        root: stack.root.clone(),
        listen: Some("0.0.0.0:0".parse().expect("addr")),
        mcap: None,
        access,
    };
    let open = roam_view::run(
        stack.router.clone(),
        config(Access::default()),
        CancellationToken::new(),
    )
    .await;
    assert!(
        matches!(open, Err(ViewError::OpenWithoutToken(_))),
        "{open:?}"
    );
    let token = Token::new(TOKEN).expect("token");
    let cancel = CancellationToken::new();
    let view = roam_view::run(
        stack.router.clone(),
        config(Access::new([APP], Some(token)).expect("access")),
        cancel.clone(),
    )
    .await
    .expect("with a token it listens on every interface");
    stop(stack, view, cancel).await;
}
