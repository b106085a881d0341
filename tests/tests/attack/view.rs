//! The live view checks who connects: a page from a foreign Origin is refused before the
//! WebSocket opens, one from the Foxglove app gets its upgrade, also while strangers
//! hold connections open sending half a head (slowloris).

use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio_util::sync::CancellationToken;

use roam_tests::{within, Harness};

/// The status line the view answers an upgrade from `origin` with.
async fn upgrade_status(addr: std::net::SocketAddr, origin: &str) -> String {
    let mut stream = within("connect", tokio::net::TcpStream::connect(addr))
        .await
        .expect("connect");
    let request = format!(
        "GET / HTTP/1.1\r\nHost: {addr}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\
         Sec-WebSocket-Protocol: foxglove.sdk.v1\r\nOrigin: {origin}\r\n\r\n"
    );
    within("send", stream.write_all(request.as_bytes()))
        .await
        .expect("send");
    let mut head = vec![0u8; 256];
    let n = within("status", stream.read(&mut head))
        .await
        .expect("read");
    let text = String::from_utf8_lossy(&head[..n]).into_owned();
    text.lines().next().unwrap_or_default().to_owned()
}

/// Starts a view with default access under the harness's root.
async fn start_view(harness: &Harness, cancel: &CancellationToken) -> roam_view::ViewHandle {
    within(
        "view start",
        roam_view::run(
            harness.router.session.clone(),
            roam_view::ViewConfig {
                root: harness.root.clone(),
                listen: Some("127.0.0.1:0".parse().expect("addr")),
                mcap: None,
                access: roam_view::Access::default(),
            },
            cancel.clone(),
        ),
    )
    .await
    .expect("view")
}

pub(crate) async fn origins(harness: &Harness) {
    let cancel = CancellationToken::new();
    let view = start_view(harness, &cancel).await;
    let addr = view.websocket_addr().expect("listening");
    let foreign = upgrade_status(addr, "https://evil.example").await;
    assert!(foreign.contains(" 403 "), "a foreign page got '{foreign}'");
    let app = upgrade_status(addr, "https://app.foxglove.dev").await;
    assert!(app.contains(" 101 "), "the Foxglove app got '{app}'");
    cancel.cancel();
    within("view stop", view.join()).await.expect("view stops");
}

/// Half-open connections held by a stranger: 40 (more than the served slots), then
/// more than the half-open places; each time a real client gets its upgrade at once.
pub(crate) async fn half_open(harness: &Harness) {
    let cancel = CancellationToken::new();
    let view = start_view(harness, &cancel).await;
    let addr = view.websocket_addr().expect("listening");
    let half = b"GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\n";
    let mut held = Vec::new();
    for count in [40, roam_view::MAX_HALF_OPEN + 40] {
        while held.len() < count {
            let mut stream = within("connect", tokio::net::TcpStream::connect(addr))
                .await
                .expect("connect");
            within("half a head", stream.write_all(half))
                .await
                .expect("send");
            held.push(stream);
        }
        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
        let app = upgrade_status(addr, "https://app.foxglove.dev").await;
        assert!(
            app.contains(" 101 "),
            "with {count} half-open connections the Foxglove app got '{app}'"
        );
    }
    drop(held);
    cancel.cancel();
    within("view stop", view.join()).await.expect("view stops");
}
