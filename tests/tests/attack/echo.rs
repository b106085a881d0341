//! Bounded, escaped echoes: a huge field comes back as a short excerpt, a flood of bad
//! puts makes a few log lines, a name with a newline or a terminal escape cannot forge a
//! log line, and a number like 1e300 is logged and answered as `1e300`, not as 301
//! digits.

use roam_proto::cells::Cells;
use roam_proto::controller::Mission;
use roam_proto::map::{CellWrite, GridMeta, LayerChange, LayerUpdate, UpdateAck};
use roam_proto::sim::{AnchorRange, LocalObservation, RangeScan};
use roam_proto::{encode, keys};
use roam_runtime::{ClientError, Requester};
use roam_tests::{within, Harness};

use crate::logs::Captured;

/// The largest error reply an echo attack may get back, bytes.
pub(crate) const MAX_ECHO_REPLY_BYTES: usize = 1024;
/// How much twenty one-megabyte bad puts to each subscriber may grow the log, bytes.
pub(crate) const MAX_FLOOD_LOG_BYTES: usize = 64 * 1024;

/// A line a forged robot name would start if it reached the log raw.
const FORGED_LINE: &str = "2026-01-01T00:00:00.000000Z  INFO roam: forged";

async fn refused_bytes(client: &Requester, key: &str, payload: Vec<u8>) -> usize {
    match client.request_raw::<UpdateAck>(key, Some(payload)).await {
        Err(ClientError::Refused(reply)) => encode(&reply).len(),
        other => panic!("expected a refusal, got {other:?}"),
    }
}

/// Replies to huge fields stay small.
pub(crate) async fn replies(harness: &Harness, client: &Requester) {
    let server = harness.start_role(harness.map_server_config()).await;
    let key = keys::map_update(&harness.root, "occupancy");
    let kind = "k".repeat(5_000_000);
    let huge_kind = format!(r#"{{"v":1,"kind":"{kind}","body":{{}}}}"#).into_bytes();
    let size = within("huge kind", refused_bytes(client, &key, huge_kind)).await;
    assert!(
        size <= MAX_ECHO_REPLY_BYTES,
        "a 5 MB kind came back in {size} bytes"
    );
    let quoted = "x".repeat(1_000_000);
    let huge_value = format!(
        r#"{{"v":1,"kind":"layer_update","body":{{"base_version":"{quoted}","change":{{}}}}}}"#
    )
    .into_bytes();
    let size = within("huge value", refused_bytes(client, &key, huge_value)).await;
    assert!(
        size <= MAX_ECHO_REPLY_BYTES,
        "a 1 MB string came back in {size} bytes"
    );
    server.stop().await.1.expect("clean stop");
}

/// Floods of bad puts make a bounded log, and forged names stay on one escaped line.
pub(crate) async fn logs(harness: &Harness, client: &Requester, log: &Captured) {
    let localization = harness.start_role(harness.localization_config(None)).await;
    let controller = harness.start_role(harness.controller_config()).await;
    let mapper = harness.start_role(harness.mapper_config()).await;
    let root = harness.root.clone();
    let session = client.session();

    let before = log.len();
    let kind = "k".repeat(1_000_000);
    let huge_kind = format!(r#"{{"v":1,"kind":"{kind}","body":{{}}}}"#);
    let long_id = Mission {
        after_step: None,
        robot: "robot".into(),
        id: "i".repeat(1_000_000),
        waypoints: vec![[1.0, 1.0]],
        recovery: false,
    };
    for _ in 0..20 {
        for leaf in ["mission", "ranges", "observation", "estimate"] {
            let key = format!("{root}/robot/robot/{leaf}");
            within("put", session.put(&key, huge_kind.as_bytes().to_vec()))
                .await
                .expect("put");
        }
        within(
            "put",
            session.put(keys::robot_mission(&root, "robot"), encode(&long_id)),
        )
        .await
        .expect("put");
    }
    // A forged name, then a valid put on the same keys so the flood has been handled
    // when the check runs (each subscriber handles its samples in order).
    let forged = Mission {
        after_step: None,
        robot: format!("robot\n{FORGED_LINE}\u{1b}[31m"),
        id: format!("id\n{FORGED_LINE}"),
        waypoints: vec![],
        recovery: false,
    };
    within(
        "put",
        session.put(keys::robot_mission(&root, "robot"), encode(&forged)),
    )
    .await
    .expect("put");
    log.wait_for(before, "the body names robot 'robot\\n2026")
        .await;
    mapper.stop().await.1.expect("clean stop");
    controller.stop().await.1.expect("clean stop");
    localization.stop().await.1.expect("clean stop");

    let grown = log.len() - before;
    let text = log.since(before);
    assert!(
        grown <= MAX_FLOOD_LOG_BYTES,
        "100 one-megabyte bad puts grew the log by {grown} bytes:\n{}",
        &text[..text.len().min(2000)]
    );
    assert!(
        !text.contains(&format!("\n{FORGED_LINE}")),
        "a forged name started a log line"
    );
    assert!(
        !text.contains('\u{1b}'),
        "a terminal escape reached the log"
    );
    assert!(
        text.contains("mission refused"),
        "the refusals are logged:\n{text}"
    );
}

/// 1e300 written out: what a number from the wire must never become in a log or a reply.
fn digits() -> String {
    format!("1{}", "0".repeat(40))
}

/// Numbers from the wire, huge ones included, reach logs and replies in a few
/// characters: a scan and an observation stamped 1e300 (localization and the mapper log
/// why they ignore them), a cell written with 1e300 (the map server's refusal).
pub(crate) async fn numbers(harness: &Harness, client: &Requester, log: &Captured) {
    let server = harness.start_role(harness.map_server_config()).await;
    let localization = harness.start_role(harness.localization_config(None)).await;
    let mapper = harness.start_role(harness.mapper_config()).await;
    let root = harness.root.clone();
    let session = client.session();
    let before = log.len();

    let scan = RangeScan {
        robot: "robot".into(),
        step: 1,
        time_s: 1e300,
        ranges: (0..3)
            .map(|i| AnchorRange {
                anchor: format!("a{i}"),
                at: [f64::from(i) * 5.0, 1e300],
                range_m: 1.0,
            })
            .collect(),
    };
    within(
        "put",
        session.put(keys::robot_ranges(&root, "robot"), encode(&scan)),
    )
    .await
    .expect("put");
    let observation = LocalObservation {
        robot: "robot".into(),
        step: 1,
        time_s: 1e300,
        at: [0.0, 0.0],
        x0: 0,
        y0: 0,
        meta: GridMeta {
            width: 1,
            height: 1,
            resolution: 0.2,
            origin: Default::default(),
        },
        cells: Cells::I8(vec![0]),
    };
    within(
        "put",
        session.put(
            keys::robot_observation(&root, "robot"),
            encode(&observation),
        ),
    )
    .await
    .expect("put");
    log.wait_for(before, "ignoring a scan: its time 1e300 s")
        .await;
    log.wait_for(before, "ignoring an observation: its time 1e300 s")
        .await;

    let huge = LayerUpdate {
        base_version: 1,
        change: LayerChange::SetCells {
            cells: vec![CellWrite {
                x: 0,
                y: 0,
                value: 1e300,
            }],
        },
        world: None,
    };
    let refused = match client
        .request::<LayerUpdate, UpdateAck>(&keys::map_update(&root, "peb"), Some(&huge))
        .await
    {
        Err(ClientError::Refused(reply)) => reply,
        other => panic!("expected a refusal, got {other:?}"),
    };
    let occupancy = match client
        .request::<LayerUpdate, UpdateAck>(&keys::map_update(&root, "occupancy"), Some(&huge))
        .await
    {
        Err(ClientError::Refused(reply)) => reply,
        other => panic!("expected a refusal, got {other:?}"),
    };
    assert!(
        occupancy.message.contains("value 1e300"),
        "{}",
        occupancy.message
    );
    for reply in [&refused, &occupancy] {
        assert!(!reply.message.contains(&digits()), "{}", reply.message);
    }
    mapper.stop().await.1.expect("clean stop");
    localization.stop().await.1.expect("clean stop");
    server.stop().await.1.expect("clean stop");
    assert!(
        !log.since(before).contains(&digits()),
        "a number from the wire was logged in full"
    );
}
