//! The Foxglove WebSocket protocol's own client, `@foxglove/ws-protocol` 0.8.0 (npm, the
//! `foxglove.websocket.v1` subprotocol Lichtblick speaks), run by Node against the live
//! view through Zenoh: it is served (the gate answers with its subprotocol), sees the
//! map's channel and receives the map, every cell of the map server's layer in it.
//!
//! Needs `node` and `npm ci` in `tests/clients/node` (the committed package-lock.json).
//! Without them the test prints a notice and passes, except in CI (`CI` set), where it
//! fails.

mod common;

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::Duration;

use common::{start_view, within, Stack};
use roam_proto::cells::Cells;
use roam_runtime::Requester;
use roam_view::Access;

fn client_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/clients/node")
}

fn node_client_ready() -> bool {
    let node = Command::new("node")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    node && client_dir()
        .join("node_modules/@foxglove/ws-protocol/package.json")
        .exists()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_ws_protocol_client_receives_the_map() {
    if !node_client_ready() {
        if std::env::var_os("CI").is_some() {
            panic!("node or tests/clients/node/node_modules is missing; CI runs `npm ci` there");
        }
        eprintln!(
            "SKIPPED the_ws_protocol_client_receives_the_map: needs node and \
             `npm ci` in tests/clients/node"
        );
        return;
    }
    let mut stack = Stack::start().await;
    stack.start_map_server().await;
    let requester = Requester::new(stack.client().await, Duration::from_secs(5));
    let occupancy = stack.occupancy(&requester).await;
    let view_session = stack.client().await;
    let (view, cancel) = start_view(&view_session, &stack.root, Access::default(), None).await;
    let url = view.websocket_url().expect("listening");

    // The script gives up by itself after 60 s.
    let output = within(
        "the node client",
        tokio::task::spawn_blocking(move || {
            Command::new("node")
                .arg(client_dir().join("foxglove_client.js"))
                .arg(&url)
                .arg("/map/occupancy")
                .current_dir(client_dir())
                .stdin(Stdio::null())
                .output()
        }),
    )
    .await
    .expect("join")
    .expect("node runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "node exited {:?}\nstdout:\n{stdout}\nstderr:\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let got: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON line");
    assert_eq!(got["subprotocol"], "foxglove.websocket.v1", "{got}");
    assert_eq!(got["topic"], "/map/occupancy");
    assert_eq!(got["schemaName"], "foxglove.Grid");
    let Cells::I8(cells) = &occupancy.cells else {
        panic!("occupancy is i8")
    };
    let cells_hex: String = cells.iter().map(|&c| format!("{:02x}", c as u8)).collect();
    let data = got["data_hex"].as_str().expect("hex");
    assert!(
        data.contains(&cells_hex),
        "the Grid message does not hold the map server's {} cells",
        cells.len()
    );
    cancel.cancel();
    let _ = view.join().await;
    stack.stop().await;
}
