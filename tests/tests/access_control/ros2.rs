//! The ROS 2 node's credentials (`ros2`) reach what `services/ros2/src/node/` uses and
//! nothing else: no robot's mission, command or estimate, no robot's plans, no map write
//! but its `--ros2-map`'s replace of `occupancy`, no ROS topic of another node's. (The
//! real node doing its job under them: `every_role_does_its_job_through_the_secure_router`.)
//!
//! Refusals are observed where the message would arrive, as in `robots.rs`: the
//! operator's and the sim's subscriptions, a ROS 2 node's (`ros-node`) subscription to
//! the whole ROS domain, and the real map server and planner, which never answer.

use roam_proto::keys;
use roam_proto::map::{
    DeleteLayer, LayerChange, LayerDeleted, LayerList, LayerUpdate, LoadMap, UpdateAck,
};
use roam_proto::planner::{Plan, PlanRequest};
use roam_ros2::attachment::Attachment;
use roam_ros2::msg::{PlanDowntimeRequest, PlanDowntimeResponse, PoseStamped};
use roam_ros2::{cdr, hash, names, types};
use roam_runtime::{ClientError, Requester};
use roam_tests::within;
use zenoh::query::{ConsolidationMode, QueryTarget};

use crate::intrusion::DENIED_QUERY_WAIT;
use crate::observe::{drain, heard_until, put, Spy};
use crate::site::secure_site;
use crate::ROOT;

/// How long a ROS 2 call through the node may take here.
const CALL_WAIT: std::time::Duration = std::time::Duration::from_secs(30);

/// A topic's rmw_zenoh key in domain 0.
fn topic_key(name: &str, ros_type: &str) -> String {
    let hash = hash::message_type_hash(ros_type).expect("hash");
    let dds = types::dds_type_name(ros_type).expect("dds type");
    names::entity_key(0, name, &dds, &hash)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_ros2_credentials_reach_only_what_the_node_uses() {
    let (_secrets, harness) = secure_site().await;
    let map_server = harness.start_role(harness.map_server_config()).await;
    let planner = harness
        .start_role(harness.planner_config("planner-0"))
        .await;
    let operator = Spy::on(&harness, "operator", &format!("{ROOT}/**")).await;
    let sim = Spy::on(&harness, "sim", &keys::robot_command_any(ROOT)).await;
    let ros = Spy::on(&harness, "ros-node", "0/**").await;
    let node = harness.client_as("ros2").await;

    // roam's side: no robot's mission, command or estimate; then a cancel on the shared
    // plan keys (what its services do when a call gives up), which the operator hears.
    for key in [
        keys::robot_mission(ROOT, "r1"),
        keys::robot_command(ROOT, "r1"),
        keys::robot_estimate(ROOT, "r1"),
        keys::robot_command_any(ROOT),
        format!("{ROOT}/**"),
    ] {
        put(&node, &key, b"forged".to_vec()).await;
    }
    let cancel = keys::planner_cancel(ROOT, "ros2-call");
    put(&node, &cancel, b"cancel".to_vec()).await;
    assert_eq!(heard_until(&operator, &cancel).await, [cancel]);
    assert_eq!(
        drain(&sim.subscriber),
        Vec::<String>::new(),
        "a command of the ROS 2 node's reached the sim's rights"
    );

    // Its queries: layers, plans on the shared key and occupancy's replace are
    // answered (the map server refuses a stale replace itself); other map writes and a
    // robot's plans never reach the services that would answer them.
    let list: LayerList = within(
        "layer list",
        node.request::<LayerList, LayerList>(&keys::map_index(ROOT), None),
    )
    .await
    .expect("the ROS 2 node lists the layers");
    let occupancy = list
        .layers
        .iter()
        .find(|l| l.name == "occupancy")
        .expect("an occupancy layer");
    let stale = LayerUpdate {
        base_version: occupancy.version + 1000,
        change: LayerChange::SetCells { cells: Vec::new() },
        world: None,
    };
    let replaced = within(
        "occupancy replace",
        node.request::<LayerUpdate, UpdateAck>(&keys::map_update(ROOT, "occupancy"), Some(&stale)),
    )
    .await;
    assert!(
        matches!(replaced, Err(ClientError::Refused(_))),
        "the map server answers the ROS 2 node's occupancy update itself: {replaced:?}"
    );
    let plan = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [-8.0, -8.0],
        goal: [6.0, -7.0],
        t_exec_s: 80.0,
        deadline_s: 5.0,
        model: roam_proto::planner::PlannerModel::Shortest,
        params: Default::default(),
        seed: 0,
        map_version: None,
        shortest: Default::default(),
        seed_route: Vec::new(),
    };
    let planned = within(
        "a shared plan",
        node.request::<PlanRequest, Plan>(&keys::planner_plan(ROOT), Some(&plan)),
    )
    .await;
    assert!(planned.is_ok(), "the ROS 2 node plans: {planned:?}");
    let asker = Requester::new(node.session().clone(), DENIED_QUERY_WAIT);
    let inflated = LayerUpdate {
        base_version: 0,
        ..stale.clone()
    };
    let outcomes = [
        (
            "update inflated",
            within(
                "update inflated",
                asker.request::<LayerUpdate, UpdateAck>(
                    &keys::map_update(ROOT, "inflated"),
                    Some(&inflated),
                ),
            )
            .await
            .map(|_| ()),
        ),
        (
            "delete occupancy",
            within(
                "delete occupancy",
                asker.request::<DeleteLayer, LayerDeleted>(
                    &keys::map_delete(ROOT, "occupancy"),
                    Some(&DeleteLayer { base_version: 0 }),
                ),
            )
            .await
            .map(|_| ()),
        ),
        (
            "load a map",
            within(
                "load",
                asker.request::<LoadMap, LayerList>(
                    &keys::map_load(ROOT),
                    Some(&LoadMap {
                        path: "depot.yaml".into(),
                        base_version: None,
                    }),
                ),
            )
            .await
            .map(|_| ()),
        ),
        (
            "plan for robot r1",
            within(
                "r1's plan",
                asker.request::<PlanRequest, Plan>(
                    &keys::planner_robot_plan(ROOT, "r1"),
                    Some(&plan),
                ),
            )
            .await
            .map(|_| ()),
        ),
    ];
    for (what, outcome) in outcomes {
        assert!(
            matches!(outcome, Err(ClientError::NoReply { .. })),
            "the ROS 2 node's '{what}' must never reach its service (no reply at all), got {outcome:?}"
        );
    }

    // ROS 2's side: no other node's topic (a robot's /r1/cmd_vel); then its own /r1/pose,
    // which a ROS 2 node hears.
    let cmd_vel = format!(
        "0/r1/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_{}",
        "0".repeat(64)
    );
    let pose = topic_key("/r1/pose", types::POSE_WITH_COVARIANCE_STAMPED);
    put(&node, &cmd_vel, b"forged".to_vec()).await;
    put(&node, &pose, b"a pose".to_vec()).await;
    assert_eq!(heard_until(&ros, &pose).await, [pose]);

    planner.stop().await.1.expect("the planner stops cleanly");
    map_server
        .stop()
        .await
        .1
        .expect("the map server stops cleanly");
    harness.close().await;
}

/// The real ROS 2 node, run with the `ros2` credentials beside a working stack, as a
/// ROS 2 node (`ros-node`) sees it through the router: its node token in the ROS graph,
/// `/robot/pose` from localization's estimates (with rmw_zenoh's attachment), and a
/// `/roam/plan_downtime` call answered with a path by roam's planner.
pub(crate) async fn assert_the_node_serves_ros_2(ros: &Requester) {
    let session = ros.session();
    let tokens = within(
        "the ROS graph",
        session
            .liveliness()
            .get("@ros2_lv/0/**")
            .timeout(std::time::Duration::from_secs(2)),
    )
    .await
    .expect("liveliness get");
    let mut graph = Vec::new();
    while let Ok(reply) = within("a graph token", tokens.recv_async()).await {
        if let Ok(sample) = reply.result() {
            graph.push(sample.key_expr().to_string());
        }
    }
    assert!(
        graph
            .iter()
            .any(|t| t.contains("/NN/") && t.ends_with("/roam")),
        "the node's token in the ROS graph: {graph:?}"
    );

    let pose = topic_key("/robot/pose", types::POSE_WITH_COVARIANCE_STAMPED);
    let poses = within("subscribe", session.declare_subscriber(&pose))
        .await
        .expect("pose subscriber");
    let sample = within("a pose", poses.recv_async())
        .await
        .expect("the node publishes the robot's pose");
    let attachment = sample.attachment().map(|a| a.to_bytes().len());
    assert_eq!(attachment, Some(33), "rmw_zenoh's attachment");

    let hash = hash::service_type_hash(types::PLAN_DOWNTIME).expect("hash");
    let dds = types::dds_type_name(types::PLAN_DOWNTIME).expect("dds type");
    let service = names::entity_key(0, "/roam/plan_downtime", &dds, &hash);
    let at = |x: f64, y: f64| {
        let mut pose = PoseStamped::default();
        pose.header.frame_id = "map".into();
        pose.pose.position.x = x;
        pose.pose.position.y = y;
        pose.pose.orientation.w = 1.0;
        pose
    };
    let request = cdr::encode(&PlanDowntimeRequest {
        start: at(-8.0, -8.0),
        goal: at(-2.0, 4.0),
        budget_s: 120.0,
        model: "model1".into(),
        seed: 1,
        deadline_s: 2.0,
    })
    .expect("cdr");
    let call = Attachment {
        sequence_number: 1,
        source_timestamp_ns: roam_ros2::attachment::now_ns(),
        gid: [7; 16],
    };
    // A ROS 2 client waits as long as it takes: the node answers within the planner's
    // reply margin, longer than Zenoh's default query timeout on a loaded machine.
    let replies = within(
        "a PlanDowntime call",
        session
            .get(&service)
            .payload(request)
            .attachment(call.to_bytes().to_vec())
            .target(QueryTarget::AllComplete)
            .consolidation(ConsolidationMode::None)
            .timeout(CALL_WAIT),
    )
    .await
    .expect("get");
    let reply = tokio::time::timeout(CALL_WAIT, replies.recv_async())
        .await
        .expect("the PlanDowntime response in time")
        .expect("the node answers the call");
    let payload = reply.result().expect("a response").payload().to_bytes();
    let response: PlanDowntimeResponse =
        cdr::decode(&payload, "PlanDowntime response", 1 << 20).expect("response");
    assert_eq!(response.error_code, "", "{response:?}");
    assert!(!response.path.poses.is_empty(), "{response:?}");
}
