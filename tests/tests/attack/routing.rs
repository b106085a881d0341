//! Keys decide: a body that names another robot than its key is refused, and nothing is
//! ever published on a key a stranger chose through a body.

use roam_proto::controller::Mission;
use roam_proto::localization::PositionEstimate;
use roam_proto::sim::{AnchorRange, RangeScan, SimControl, SimStatus};
use roam_proto::{decode, encode, keys, Message};
use roam_runtime::Requester;
use roam_tests::{within, Harness};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

type Sub = Subscriber<FifoChannelHandler<Sample>>;

async fn put<T: Message>(client: &Requester, key: &str, message: &T) {
    within("put", client.session().put(key, encode(message)))
        .await
        .expect("put");
}

async fn step(client: &Requester, root: &str, n: u32) -> SimStatus {
    within(
        "step",
        client.request(&keys::sim_control(root), Some(&SimControl::Step { n })),
    )
    .await
    .expect("step")
}

/// The built-in world's robot is `robot`; a stranger tries to drive it through another
/// key, and to make localization publish on wildcard keys.
pub(crate) async fn keys_decide(harness: &Harness, client: &Requester) {
    let root = harness.root.clone();
    let sim = harness.start_role(harness.sim_config(None)).await;
    let localization = harness.start_role(harness.localization_config(None)).await;
    let controller = harness.start_role(harness.controller_config()).await;
    let everything: Sub = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(format!("{root}/robot/**")),
    )
    .await
    .expect("subscriber");

    // 1. A mission on robot AAA's key whose body names robot `robot`.
    let forged = Mission {
        after_step: None,
        robot: "robot".into(),
        id: "forged".into(),
        waypoints: vec![[9.0, 9.0]],
        recovery: false,
    };
    put(client, &keys::robot_mission(&root, "AAA"), &forged).await;
    // 2. Scans whose bodies name key syntax, on the real robot's key and on a wildcard.
    for name in ["*", "**", "a/b", "robot/**"] {
        let scan = RangeScan {
            robot: name.into(),
            step: 1,
            time_s: 0.1,
            ranges: (0..4)
                .map(|i| AnchorRange {
                    anchor: format!("a{i}"),
                    at: [f64::from(i) * 5.0, f64::from(i % 2) * 5.0],
                    range_m: 3.0,
                })
                .collect(),
        };
        put(client, &keys::robot_ranges(&root, "robot"), &scan).await;
        put(client, &format!("{root}/robot/*/ranges"), &scan).await;
    }
    // The world runs on: the robot's estimates go on, the robot stays where it is.
    let before = step(client, &root, 1).await;
    let at_start = before
        .robots
        .iter()
        .find(|r| r.name == "robot")
        .expect("robot")
        .at;
    let after = step(client, &root, 40).await;
    let at_end = after
        .robots
        .iter()
        .find(|r| r.name == "robot")
        .expect("robot")
        .at;
    assert_eq!(at_start, at_end, "a forged mission moved the robot");
    // Every sample under robot/** until the estimate of the last step: each estimate is
    // on the real robot's key, and nothing was commanded.
    let mut estimates = 0;
    loop {
        let sample = within(
            "samples up to the last step's estimate",
            everything.recv_async(),
        )
        .await
        .expect("sample");
        let key = sample.key_expr().as_str().to_owned();
        if key.ends_with("/cmd") || key.ends_with("/controller") {
            panic!("the forged mission was acted on: '{key}'");
        }
        if !key.ends_with("/estimate") {
            continue;
        }
        assert_eq!(
            keys::robot_of(&root, &key),
            Some("robot"),
            "an estimate on '{key}': only the real robot's key may carry one"
        );
        let e: PositionEstimate = decode(&sample.payload().to_bytes()).expect("estimate");
        assert_eq!(e.robot, "robot");
        estimates += 1;
        if e.step >= after.step {
            break;
        }
    }
    // Estimates are published as `Delivery::Latest` (the next supersedes this one), so
    // a loaded machine may drop a few of the 40 steps' (37 seen beside the test suite);
    // what is checked is that they flow on the real robot's key, not that none drops.
    assert!(
        estimates >= 30,
        "the real robot's estimates flow ({estimates} of 40 steps)"
    );
    controller.stop().await.1.expect("clean stop");
    localization.stop().await.1.expect("clean stop");
    sim.stop().await.1.expect("clean stop");
}
