//! The live view checks who connects: a page from a foreign Origin is refused before the
//! WebSocket opens, one from the Foxglove app gets its upgrade.

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

pub(crate) async fn origins(harness: &Harness) {
    let cancel = CancellationToken::new();
    let view = within(
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
    .expect("view");
    let addr = view.websocket_addr().expect("listening");
    let foreign = upgrade_status(addr, "https://evil.example").await;
    assert!(foreign.contains(" 403 "), "a foreign page got '{foreign}'");
    let app = upgrade_status(addr, "https://app.foxglove.dev").await;
    assert!(app.contains(" 101 "), "the Foxglove app got '{app}'");
    cancel.cancel();
    within("view stop", view.join()).await.expect("view stops");
}
