//! What strangers on the stack's keys can make the view do, through real Zenoh sessions
//! on loopback: a 60 MB mission is dropped unread, a thousand missions for robots that do
//! not exist leave the robots kept bounded (and the sim's own robot drawn), and names with
//! newlines and terminal escapes reach neither an entity nor a log line raw.

mod common;

use std::collections::BTreeSet;

use common::{
    mission, put, start_view, until_stats, upgrade, within, FoxgloveClient, Stack, SUBPROTOCOL,
};
use foxglove::messages::SceneUpdate;
use foxglove::Decode;
use roam_proto::controller::MAX_WAYPOINTS;
use roam_proto::localization::PositionEstimate;
use roam_proto::sim::{GroundTruth, NamedPoint, SimStatus};
use roam_proto::{encode, keys};
use roam_view::{Access, MAX_ROBOTS, MISSION_TOPIC};
use zenoh::Wait;

/// The entities of every `SceneUpdate` a client receives until its stream goes quiet.
async fn entities(client: &mut FoxgloveClient) -> Vec<foxglove::messages::SceneEntity> {
    let mut all = Vec::new();
    for (_, payload) in client
        .drain_message_data(std::time::Duration::from_millis(500))
        .await
    {
        let update = SceneUpdate::decode(payload.as_slice()).expect("a SceneUpdate");
        all.extend(update.entities);
    }
    all
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_60_mb_mission_is_dropped_unread_and_a_full_one_is_drawn_within_the_caps() {
    let stack = Stack::start().await;
    let (view, cancel) = start_view(&stack.router, &stack.root, Access::default(), None).await;
    let client = stack.client().await;
    let key = keys::robot_mission(&stack.root, "r1");

    // A valid mission, six million waypoints: were it read, it would decode and then be
    // refused for its waypoints, which is counted apart from "over the cap, unread".
    let huge = encode(&mission("r1", "huge", 6_000_000));
    assert!(huge.len() > 60_000_000, "{} bytes", huge.len());
    put(&client, key.clone(), huge).await;
    let stats = until_stats(&view, "the huge mission", |s| s.dropped >= 1).await;
    assert_eq!(
        (stats.oversized, stats.dropped, stats.robots),
        (1, 1, 0),
        "{stats:?}"
    );

    // Under the byte cap but over the controller's waypoint limit: read, then refused.
    let over = encode(&mission("r1", "over", MAX_WAYPOINTS + 1));
    assert!(over.len() < roam_view::wire::MAX_MISSION_BYTES);
    put(&client, key.clone(), over).await;
    let stats = until_stats(&view, "the long mission", |s| s.dropped >= 2).await;
    assert_eq!((stats.oversized, stats.robots), (1, 0), "{stats:?}");

    // At the limit: drawn, its line through every waypoint, its cubes capped.
    put(&client, key, encode(&mission("r1", "full", MAX_WAYPOINTS))).await;
    let stats = until_stats(&view, "the full mission", |s| s.robots == 1).await;
    assert_eq!(stats.dropped, 2, "{stats:?}");
    let url = format!("ws://{}", view.websocket_addr().expect("listening"));
    let (mut ws, _) = FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[]))
        .await
        .expect("connects");
    ws.subscribe_topic(1, MISSION_TOPIC).await;
    let drawn = entities(&mut ws).await;
    assert_eq!(drawn.len(), 1);
    assert_eq!(drawn[0].id, "mission/r1");
    assert_eq!(drawn[0].lines[0].points.len(), MAX_WAYPOINTS);
    assert!(drawn[0].cubes.len() <= roam_view::convert::MISSION_CUBES);

    cancel.cancel();
    within("view stop", view.join())
        .await
        .expect("a clean stop");
    let _ = within("client close", client.close()).await;
    stack.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_thousand_missions_for_unknown_robots_leave_the_robots_kept_bounded() {
    let mut stack = Stack::start().await;
    stack.start_sim(20.0).await;
    let (view, cancel) = start_view(&stack.router, &stack.root, Access::default(), None).await;
    until_stats(&view, "the sim's robots", |s| s.sim_robots == 1).await;
    let url = format!("ws://{}", view.websocket_addr().expect("listening"));
    let (mut live, _) = FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[]))
        .await
        .expect("connects");
    live.subscribe_topic(1, MISSION_TOPIC).await;

    let client = stack.client().await;
    let sims = keys::robot_mission(&stack.root, "robot");
    put(&client, sims.clone(), encode(&mission("robot", "first", 3))).await;
    for i in 0..1000 {
        let ghost = format!("ghost-{i}");
        let key = keys::robot_mission(&stack.root, &ghost);
        put(&client, key, encode(&mission(&ghost, "boo", 3))).await;
    }
    // Once the sim's robot's next mission is drawn, every ghost before it has been seen
    // (or dropped by the subscriber's ring, which keeps the latest 256).
    put(&client, sims, encode(&mission("robot", "marker", 3))).await;
    within("the marker", async {
        loop {
            let (_, payload) = live.next_message_data().await;
            let update = SceneUpdate::decode(payload.as_slice()).expect("a SceneUpdate");
            let marked = update.entities.iter().any(|e| {
                e.id == "mission/robot" && e.metadata.iter().any(|kv| kv.value == "marker")
            });
            if marked {
                break;
            }
        }
    })
    .await;

    let stats = view.stats();
    assert_eq!(stats.robots, MAX_ROBOTS, "{stats:?}");
    // A client that connects now gets what is kept: at most MAX_ROBOTS missions, the
    // sim's robot's among them.
    let (mut late, _) = FoxgloveClient::try_connect(upgrade(&url, SUBPROTOCOL, &[]))
        .await
        .expect("connects");
    late.subscribe_topic(1, MISSION_TOPIC).await;
    let kept: BTreeSet<String> = entities(&mut late)
        .await
        .into_iter()
        .map(|e| e.id)
        .collect();
    assert_eq!(kept.len(), MAX_ROBOTS);
    assert!(
        kept.contains("mission/robot"),
        "the sim's robot was evicted"
    );
    assert!(kept.contains("mission/ghost-999"));
    assert!(
        !kept.contains("mission/ghost-0"),
        "the oldest ghost is gone"
    );

    cancel.cancel();
    within("view stop", view.join())
        .await
        .expect("a clean stop");
    let _ = within("client close", client.close()).await;
    stack.stop().await;
}

/// A name that would forge a log line and recolour a terminal, were it printed raw.
const EVIL: &str = "r1\nFORGED roam: all good\u{1b}[31m";

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn names_with_newlines_and_escapes_reach_no_entity_or_log_line_raw() {
    let logs = common::captured_logs();
    let stack = Stack::start().await;
    // A sim that names an evil robot and an evil anchor.
    let status = SimStatus {
        scenario: "evil".into(),
        seed: 0,
        step: 1,
        time_s: 0.4,
        running: false,
        rate: 1.0,
        step_s: 0.4,
        late_steps: 0,
        free_steps: 0,
        pending: Vec::new(),
        robots: vec![
            NamedPoint {
                name: EVIL.into(),
                at: [0.0, 0.0],
            },
            NamedPoint {
                name: "ok-1".into(),
                at: [1.0, 1.0],
            },
        ],
        anchors: vec![NamedPoint {
            name: EVIL.into(),
            at: [2.0, 2.0],
        }],
    };
    let sim_key = keys::sim_control(&stack.root);
    let reply = encode(&status);
    let sim = within(
        "fake sim",
        stack
            .router
            .declare_queryable(sim_key.clone())
            .callback(move |query| {
                let _ = query.reply(query.key_expr().clone(), reply.clone()).wait();
            }),
    )
    .await
    .expect("queryable");
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("evil.mcap");
    let (view, cancel) = start_view(
        &stack.router,
        &stack.root,
        Access::default(),
        Some(path.clone()),
    )
    .await;
    until_stats(&view, "the sim's status", |s| s.sim_robots == 1).await;

    let client = stack.client().await;
    let r1 = |kind: &str| format!("{}/robot/r1/{kind}", stack.root);
    // An evil robot name on r1's keys: dropped.
    put(&client, r1("mission"), encode(&mission(EVIL, "m", 2))).await;
    let truth = GroundTruth {
        robot: EVIL.into(),
        step: 1,
        time_s: 0.4,
        at: [0.0, 0.0],
    };
    put(&client, r1("truth"), encode(&truth)).await;
    // r1's own, with an evil mission id and evil anchors used: drawn, escaped.
    put(&client, r1("mission"), encode(&mission("r1", EVIL, 2))).await;
    let estimate = PositionEstimate {
        robot: "r1".into(),
        step: 1,
        time_s: 0.4,
        position: [0.0, 0.0],
        crb: None,
        peb_m: None,
        anchors_used: vec![EVIL.into(); 3],
        degraded: false,
    };
    put(&client, r1("estimate"), encode(&estimate)).await;
    // Garbage with an evil string in it, on a key with an escape in it.
    let evil_key = format!("{}/robot/ev\u{1b}[2Jil/mission", stack.root);
    put(&client, evil_key, EVIL.as_bytes().to_vec()).await;
    // One for the sim's robot name, two for r1's keys, one for the garbage.
    let stats = until_stats(&view, "the evil messages", |s| {
        s.dropped >= 4 && s.robots == 1
    })
    .await;
    assert_eq!(stats.dropped, 4, "{stats:?}");

    cancel.cancel();
    within("view stop", view.join())
        .await
        .expect("a clean stop");
    drop(sim);
    let _ = within("client close", client.close()).await;
    stack.stop().await;

    let recorded = std::fs::read(&path).expect("the recording");
    let raw = |hay: &[u8], needle: &str| hay.windows(needle.len()).any(|w| w == needle.as_bytes());
    // The escaped name is there (so the evil strings did reach the drawings) and the raw
    // one is nowhere in the file.
    assert!(
        raw(&recorded, "r1\\nFORGED roam: all good\\u{1b}[31m"),
        "not drawn escaped"
    );
    assert!(
        !raw(&recorded, "\nFORGED"),
        "a raw newline in the recording"
    );
    assert!(!raw(&recorded, "\u{1b}["), "a raw escape in the recording");
    let mut topics = BTreeSet::new();
    for message in mcap::MessageStream::new(&recorded).expect("messages") {
        let message = message.expect("a message");
        topics.insert(message.channel.topic.clone());
    }
    for topic in ["/anchors", "/robots/mission", "/robots/estimate"] {
        assert!(topics.contains(topic), "{topic} not in {topics:?}");
    }

    let text = logs.lock().expect("logs").clone();
    assert!(raw(&text, "FORGED"), "the evil strings were logged escaped");
    assert!(!raw(&text, "\nFORGED"), "a raw newline in the log");
    assert!(!raw(&text, "\u{1b}["), "a raw escape in the log");
}
