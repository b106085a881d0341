//! The ROS 2 node under a stranger's calls, through Zenoh as rmw_zenoh would carry them.
//!
//! - `/roam/get_plan` and `/roam/plan_downtime`: a query without rmw_zenoh's attachment
//!   gets an error reply, a CDR payload of 8 MB gets a refusal (`malformed`, or an empty
//!   path: GetPlan has no error field), and a storm of calls is answered call by call
//!   (planned, or refused at once past the node's capacity); none is left waiting, and
//!   the node answers a good call afterwards.
//! - `--ros2-map`: an OccupancyGrid whose header claims 10⁸ cells with a short payload is
//!   refused from its header, with the reason logged, and the process's peak memory does
//!   not grow by anything near 10⁸ cells; a good map after it is taken.

use std::time::{Duration, Instant};

use roam_proto::keys;
use roam_proto::map::LayerList;
use roam_ros2::attachment::Attachment;
use roam_ros2::msg::{
    GetPlanRequest, GetPlanResponse, MapMetaData, OccupancyGrid, PlanDowntimeRequest,
    PlanDowntimeResponse, PoseStamped,
};
use roam_ros2::node::{Ros2Config, GET_PLAN_ANSWER_S, MAX_CONCURRENT_CALLS};
use roam_ros2::{cdr, hash, names, types};
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::Requester;
use roam_tests::{within, Harness};
use zenoh::query::{ConsolidationMode, QueryTarget};

use crate::logs::Captured;

/// Calls of each service in the storm, all at once.
const STORM: usize = 300;
/// How long any one call may wait for its answer: a planned GetPlan call's own bound,
/// and room for a loaded debug build.
const ANSWER_WITHIN: Duration = Duration::from_secs(GET_PLAN_ANSWER_S as u64 + 30);

/// A service's rmw_zenoh key (domain 0, the node's default namespace).
fn service_key(name: &str, ros_type: &str) -> String {
    let hash = hash::service_type_hash(ros_type).expect("hash");
    let dds = types::dds_type_name(ros_type).expect("dds type");
    names::entity_key(0, name, &dds, &hash)
}

fn pose(x: f64, y: f64) -> PoseStamped {
    let mut pose = PoseStamped::default();
    pose.header.frame_id = "map".into();
    pose.pose.position.x = x;
    pose.pose.position.y = y;
    pose.pose.orientation.w = 1.0;
    pose
}

/// A call's answer: `Ok(payload)` for a reply, `Err(text)` for an error reply.
type Answer = Result<Vec<u8>, String>;

/// One call as a ROS 2 client makes it (target all complete queryables, no
/// consolidation), with the attachment when `sequence` is given; the first answer.
async fn call(
    session: &zenoh::Session,
    key: &str,
    payload: Vec<u8>,
    sequence: Option<i64>,
) -> Answer {
    let mut get = session
        .get(key)
        .payload(payload)
        .target(QueryTarget::AllComplete)
        .consolidation(ConsolidationMode::None)
        .timeout(ANSWER_WITHIN);
    if let Some(sequence_number) = sequence {
        let attachment = Attachment {
            sequence_number,
            source_timestamp_ns: roam_ros2::attachment::now_ns(),
            gid: [9; 16],
        };
        get = get.attachment(attachment.to_bytes().to_vec());
    }
    let replies = get.await.expect("get");
    let reply = replies
        .recv_async()
        .await
        .unwrap_or_else(|_| panic!("a call to {key} was left without an answer"));
    match reply.result() {
        Ok(sample) => Ok(sample.payload().to_bytes().to_vec()),
        Err(error) => Err(String::from_utf8_lossy(&error.payload().to_bytes()).into_owned()),
    }
}

fn get_plan_request() -> Vec<u8> {
    cdr::encode(&GetPlanRequest {
        start: pose(-8.0, -8.0),
        goal: pose(-2.0, 4.0),
        tolerance: 0.0,
    })
    .expect("cdr")
}

fn plan_downtime_request() -> Vec<u8> {
    cdr::encode(&PlanDowntimeRequest {
        start: pose(-8.0, -8.0),
        goal: pose(-2.0, 4.0),
        budget_s: 120.0,
        model: "model1".into(),
        seed: 1,
        deadline_s: 2.0,
    })
    .expect("cdr")
}

/// A CDR payload of 8 MB: the encapsulation header, then bytes no request is made of.
fn huge_payload() -> Vec<u8> {
    let mut payload = cdr::CDR_LE.to_vec();
    payload.resize(8 * 1024 * 1024, 0x41);
    payload
}

pub(crate) async fn services(harness: &Harness, client: &Requester) {
    let map_server = harness.start_role(harness.map_server_config()).await;
    let planner = harness.start_role(harness.planner_config("p1")).await;
    let node = harness
        .start_role(Ros2Config {
            service: ServiceConfig::at(harness.root.clone()),
            ..Ros2Config::default()
        })
        .await;
    let session = client.session().clone();
    let get_plan = service_key("/roam/get_plan", types::GET_PLAN);
    let plan_downtime = service_key("/roam/plan_downtime", types::PLAN_DOWNTIME);

    // No attachment: not an rmw_zenoh call, answered with an error reply.
    for key in [&get_plan, &plan_downtime] {
        let answer = within(
            "no attachment",
            call(&session, key, get_plan_request(), None),
        )
        .await;
        let error = answer.expect_err("an error reply");
        assert!(error.contains("attachment"), "{error}");
    }

    // 8 MB of CDR: refused, as the service's response.
    let answer = within(
        "huge GetPlan",
        call(&session, &get_plan, huge_payload(), Some(1)),
    )
    .await
    .expect("a GetPlan response");
    let response: GetPlanResponse =
        cdr::decode(&answer, "GetPlan response", 1 << 20).expect("response");
    assert!(response.plan.poses.is_empty(), "an empty path");
    let answer = within(
        "huge PlanDowntime",
        call(&session, &plan_downtime, huge_payload(), Some(2)),
    )
    .await
    .expect("a PlanDowntime response");
    let response: PlanDowntimeResponse =
        cdr::decode(&answer, "PlanDowntime response", 1 << 20).expect("response");
    assert_eq!(response.error_code, "malformed", "{response:?}");
    assert!(
        response.error_message.contains("bytes"),
        "{}",
        response.error_message
    );

    // A storm of both at once: every call answered, none waiting.
    let started = Instant::now();
    let mut calls = Vec::with_capacity(2 * STORM);
    for i in 0..STORM {
        for (get, key, payload) in [
            (true, get_plan.clone(), get_plan_request()),
            (false, plan_downtime.clone(), plan_downtime_request()),
        ] {
            let session = session.clone();
            calls.push(tokio::spawn(async move {
                (
                    get,
                    call(&session, &key, payload, Some(10 + i as i64)).await,
                )
            }));
        }
    }
    let (mut paths, mut empty) = (0, 0);
    let mut refused = std::collections::BTreeMap::<String, usize>::new();
    for task in calls {
        let (get, answer) = task.await.expect("call task");
        let answer = answer.expect("a response, not an error reply");
        if get {
            let r: GetPlanResponse = cdr::decode(&answer, "GetPlan", 1 << 20).expect("GetPlan");
            if r.plan.poses.is_empty() {
                empty += 1;
            } else {
                paths += 1;
            }
        } else {
            let r: PlanDowntimeResponse =
                cdr::decode(&answer, "PlanDowntime", 1 << 20).expect("PlanDowntime");
            if r.error_code.is_empty() {
                paths += 1;
            } else {
                *refused.entry(r.error_code).or_default() += 1;
            }
        }
    }
    eprintln!(
        "ROS 2 storm: {} calls answered in {:.1} s: {paths} with a path, {empty} empty, refused {refused:?}",
        2 * STORM,
        started.elapsed().as_secs_f64()
    );
    assert!(
        empty + refused.values().sum::<usize>() >= 2 * (STORM - MAX_CONCURRENT_CALLS),
        "calls past the node's capacity are answered at once"
    );

    // The node is up and answers a good call.
    assert!(harness.is_live(roam_ros2::node::SERVICE_NAME).await);
    let answer = within(
        "a good call after the attack",
        call(
            &session,
            &plan_downtime,
            plan_downtime_request(),
            Some(9999),
        ),
    )
    .await
    .expect("a response");
    let response: PlanDowntimeResponse =
        cdr::decode(&answer, "PlanDowntime response", 1 << 20).expect("response");
    assert!(
        response.error_code.is_empty() && !response.path.poses.is_empty(),
        "{response:?}"
    );
    node.stop().await.1.expect("clean stop");
    planner.stop().await.1.expect("clean stop");
    map_server.stop().await.1.expect("clean stop");
}

/// The process's peak resident memory since [`reset_peak`], KiB; `None` where Linux's
/// `/proc/self/status` is not there.
fn peak_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Starts the peak over from the memory resident now (Linux: `5` to `clear_refs`).
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

async fn occupancy_version(client: &Requester, root: &str) -> u64 {
    let list: LayerList = within(
        "layers",
        client.request::<LayerList, LayerList>(&keys::map_index(root), None),
    )
    .await
    .expect("layers");
    list.layers
        .iter()
        .find(|l| l.name == "occupancy")
        .map_or(0, |l| l.version)
}

fn grid(width: u32, height: u32, data: Vec<i8>) -> OccupancyGrid {
    let mut grid = OccupancyGrid {
        info: MapMetaData {
            resolution: 0.5,
            width,
            height,
            ..MapMetaData::default()
        },
        data,
        ..OccupancyGrid::default()
    };
    grid.header.frame_id = "map".into();
    grid
}

pub(crate) async fn map_input(harness: &Harness, client: &Requester, log: &Captured) {
    let map_server = harness.start_role(harness.map_server_config()).await;
    let node = harness
        .start_role(Ros2Config {
            service: ServiceConfig::at(harness.root.clone()),
            map_input: Some("/map".into()),
            ..Ros2Config::default()
        })
        .await;
    let hash = hash::message_type_hash(types::OCCUPANCY_GRID).expect("hash");
    let dds = types::dds_type_name(types::OCCUPANCY_GRID).expect("dds");
    let key = names::entity_key(0, "/map", &dds, &hash);
    let session = client.session().clone();
    let put = |sequence_number: i64, grid: OccupancyGrid| {
        let (session, key) = (session.clone(), key.clone());
        async move {
            let attachment = Attachment {
                sequence_number,
                source_timestamp_ns: roam_ros2::attachment::now_ns(),
                gid: [7; 16],
            };
            within(
                "put",
                session
                    .put(key, cdr::encode(&grid).expect("cdr"))
                    .attachment(attachment.to_bytes().to_vec()),
            )
            .await
            .expect("put");
        }
    };
    let before = occupancy_version(client, &harness.root).await;
    let from = log.len();
    let measured = reset_peak();
    let peak_before = peak_kib();

    // 10⁸ cells claimed (10,000 × 10,000), 16 sent.
    put(1, grid(10_000, 10_000, vec![0; 16])).await;
    log.wait_for(from, "100000000 cells").await;
    let refusal = log.since(from);
    assert!(refusal.contains("max_layer_cells"), "{refusal}");
    if let (true, Some(a), Some(b)) = (measured, peak_before, peak_kib()) {
        let grown_mib = b.saturating_sub(a) / 1024;
        eprintln!("the 10⁸-cell map grew the peak by {grown_mib} MiB");
        assert!(
            grown_mib < 48,
            "a 10⁸-cell header grew the peak by {grown_mib} MiB"
        );
    }
    assert_eq!(occupancy_version(client, &harness.root).await, before);

    // The stack keeps going: a good map is taken.
    put(2, grid(4, 2, vec![0, 0, 100, 0, -1, 0, 0, 100])).await;
    let deadline = Instant::now() + roam_tests::STEP;
    while occupancy_version(client, &harness.root).await <= before {
        assert!(Instant::now() < deadline, "the good map was not taken");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    node.stop().await.1.expect("clean stop");
    map_server.stop().await.1.expect("clean stop");
}
