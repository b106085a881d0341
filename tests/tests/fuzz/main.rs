//! Bad input: every queryable and every subscriber of a running stack is fed random and
//! mutated payloads from a seeded RNG (reproducible), well over 100,000 in one bounded
//! run. No service may panic or hang, every query gets exactly one reply, a payload
//! that is not a valid request gets a structured `ErrorReply`, and afterwards every
//! service is still live and answers a normal request.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roam_proto::controller::Mission;
use roam_proto::localization::{PebQuery, PebReply, PebWhere, PositionEstimate};
use roam_proto::map::{
    CellWrite, DeleteLayer, GridMeta, Layer, LayerChange, LayerDeleted, LayerList, LayerUpdate,
    LoadMap, Origin, UpdateAck,
};
use roam_proto::mapper::MapperStatus;
use roam_proto::planner::{CancelPlan, GaOverrides, Plan, PlanRequest, PlannerModel};
use roam_proto::sim::{
    AnchorRange, LocalObservation, NamedPoint, RangeScan, RobotCommand, SimClock, SimControl,
    SimStatus,
};
use roam_proto::{cells::Cells, decode, encode, keys, ErrorReply};
use roam_tests::{within, Harness};
use zenoh::Session;

mod bases;
mod mutate;
mod send;

use bases::*;

/// How long the put storm may go on once the query storm has ended.
const PUT_STORM_BOUND: Duration = Duration::from_secs(120);
use mutate::*;
use send::*;

const SEED: u64 = 0x5eed_f022;
/// Panics anywhere in this test binary (service tasks, blocking workers, Zenoh
/// callbacks): a panicking subscriber task would otherwise only stop itself.
static PANICS: AtomicUsize = AtomicUsize::new(0);
/// Queries in flight at once.
const IN_FLIGHT: usize = 32;
/// How long one query may wait for its reply (a GA plan under load is the slowest).
const QUERY_TIMEOUT: Duration = Duration::from_secs(20);

/// Which message a query key decodes, so the test knows when a refusal is required.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expects {
    LayerUpdate,
    DeleteLayer,
    LoadMap,
    PlanRequest,
    SimControl,
    PebQuery,
    /// The queryable ignores the payload (index, layer get, mapper status).
    Nothing,
}

impl Expects {
    /// Whether the service must refuse `bytes` because it does not decode as its request.
    fn must_refuse(self, bytes: &[u8]) -> bool {
        match self {
            Expects::LayerUpdate => decode::<LayerUpdate>(bytes).is_err(),
            Expects::DeleteLayer => decode::<DeleteLayer>(bytes).is_err(),
            Expects::LoadMap => decode::<LoadMap>(bytes).is_err(),
            Expects::PlanRequest => decode::<PlanRequest>(bytes).is_err(),
            Expects::SimControl => decode::<SimControl>(bytes).is_err(),
            Expects::PebQuery => decode::<PebQuery>(bytes).is_err(),
            Expects::Nothing => false,
        }
    }

    /// Whether a successful reply decodes as what this key answers with.
    fn reply_decodes(self, bytes: &[u8]) -> bool {
        match self {
            Expects::LayerUpdate => decode::<UpdateAck>(bytes).is_ok(),
            Expects::DeleteLayer => decode::<LayerDeleted>(bytes).is_ok(),
            Expects::LoadMap => decode::<LayerList>(bytes).is_ok(),
            Expects::PlanRequest => decode::<Plan>(bytes).is_ok(),
            Expects::SimControl => decode::<SimStatus>(bytes).is_ok(),
            Expects::PebQuery => decode::<PebReply>(bytes).is_ok(),
            Expects::Nothing => {
                decode::<LayerList>(bytes).is_ok()
                    || decode::<Layer>(bytes).is_ok()
                    || decode::<MapperStatus>(bytes).is_ok()
            }
        }
    }
}

/// One fuzzed key: where, what it decodes, valid messages to mutate, how many payloads.
struct Target {
    key: String,
    expects: Expects,
    bases: Vec<Vec<u8>>,
    count: usize,
}

// ---------------------------------------------------------------------------------------
// Payloads.

const KINDS: &[&str] = &[
    "layer",
    "layer_list",
    "layer_update",
    "update_ack",
    "delete_layer",
    "layer_deleted",
    "load_map",
    "plan_request",
    "plan",
    "cancel_plan",
    "sim_control",
    "sim_status",
    "sim_clock",
    "robot_command",
    "range_scan",
    "observation",
    "position_estimate",
    "peb_query",
    "mission",
    "mapper_status",
    "error",
    "",
    "LAYER",
];

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn every_queryable_and_subscriber_survives_random_and_mutated_payloads() {
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        PANICS.fetch_add(1, Ordering::SeqCst);
        default_hook(info);
    }));
    let started = Instant::now();
    let harness = Harness::start().await;
    let map_server = harness.start_role(harness.map_server_config()).await;
    let planner = harness.start_role(harness.planner_config("p1")).await;
    let sim = harness.start_role(harness.sim_config(None)).await;
    let localization = harness.start_role(harness.localization_config(None)).await;
    let controller = harness.start_role(harness.controller_config()).await;
    let mapper = harness.start_role(harness.mapper_config()).await;
    let client = harness.client().await;
    let session = client.session().clone();
    let root = harness.root.clone();

    // The real planner layers, to give the planner its map back after the storm (a
    // layer publication with a higher version replaces the one it plans on).
    let inflated: Layer = within(
        "inflated",
        client.request::<Layer, Layer>(&keys::map_layer(&root, "inflated"), None),
    )
    .await
    .expect("inflated layer");
    let information: Layer = within(
        "information",
        client.request::<Layer, Layer>(&keys::map_layer(&root, "information"), None),
    )
    .await
    .expect("information layer");
    let index: LayerList = within(
        "index",
        client.request::<LayerList, LayerList>(&keys::map_index(&root), None),
    )
    .await
    .expect("index");
    let occupancy_version = index
        .layers
        .iter()
        .find(|l| l.name == "occupancy")
        .map_or(1, |l| l.version);

    let q = |key: String, expects, bases: Vec<Vec<u8>>, count| Target {
        key,
        expects,
        bases,
        count,
    };
    let queries = vec![
        q(
            keys::map_update(&root, "occupancy"),
            Expects::LayerUpdate,
            layer_bases(occupancy_version),
            3000,
        ),
        q(
            keys::map_update(&root, "fuzz"),
            Expects::LayerUpdate,
            layer_bases(0),
            2000,
        ),
        q(
            keys::map_update(&root, "inflated"),
            Expects::LayerUpdate,
            layer_bases(1),
            1000,
        ),
        q(
            keys::map_delete(&root, "fuzz"),
            Expects::DeleteLayer,
            delete_bases(),
            1000,
        ),
        q(
            keys::map_delete(&root, "occupancy"),
            Expects::DeleteLayer,
            delete_bases(),
            500,
        ),
        q(keys::map_load(&root), Expects::LoadMap, load_bases(), 2000),
        q(keys::map_index(&root), Expects::Nothing, vec![], 1500),
        q(
            keys::map_layer(&root, "information"),
            Expects::Nothing,
            vec![],
            300,
        ),
        q(
            keys::planner_plan(&root),
            Expects::PlanRequest,
            plan_bases(),
            3500,
        ),
        q(
            keys::sim_control(&root),
            Expects::SimControl,
            sim_bases(),
            3000,
        ),
        q(
            keys::localization_peb(&root),
            Expects::PebQuery,
            peb_bases(),
            3000,
        ),
        q(keys::mapper_status(&root), Expects::Nothing, vec![], 1500),
    ];
    let puts = vec![
        q(
            keys::robot_command(&root, "robot"),
            Expects::Nothing,
            command_bases(),
            11_000,
        ),
        q(
            keys::robot_ranges(&root, "robot"),
            Expects::Nothing,
            ranges_bases(),
            11_000,
        ),
        q(
            keys::robot_observation(&root, "robot"),
            Expects::Nothing,
            observation_bases(),
            11_000,
        ),
        q(
            keys::robot_estimate(&root, "robot"),
            Expects::Nothing,
            estimate_bases(),
            11_000,
        ),
        q(
            keys::robot_mission(&root, "robot"),
            Expects::Nothing,
            mission_bases(),
            9_000,
        ),
        q(
            keys::planner_cancel(&root, "x"),
            Expects::Nothing,
            cancel_bases(),
            8_000,
        ),
        q(
            keys::map_layer(&root, "occupancy"),
            Expects::Nothing,
            layer_message_bases("occupancy"),
            3_000,
        ),
        q(
            keys::map_layer(&root, "inflated"),
            Expects::Nothing,
            layer_message_bases("inflated"),
            3_000,
        ),
        q(
            keys::map_layer(&root, "information"),
            Expects::Nothing,
            layer_message_bases("information"),
            3_000,
        ),
        q(
            keys::map_layer(&root, "peb"),
            Expects::Nothing,
            layer_message_bases("peb"),
            3_000,
        ),
        q(
            keys::sim_clock(&root),
            Expects::Nothing,
            clock_bases(),
            7_000,
        ),
    ];
    // Every valid message of every kind, for wrong-kind payloads and splices.
    let all: Arc<Vec<Vec<u8>>> = Arc::new(
        queries
            .iter()
            .chain(puts.iter())
            .flat_map(|t| t.bases.iter().cloned())
            .collect(),
    );

    let storm = Instant::now();
    let put_task = tokio::spawn(storm_puts(session.clone(), puts, all.clone(), SEED + 1));
    let query_outcomes = storm_queries(session.clone(), queries, all, SEED).await;
    // The put storm is 80,000 payloads sent one after another beside the
    // queries; it is not one test step, so it gets its own bound (a loaded
    // 2-core CI machine took more than queries + 10 s on a clean build).
    let put_counts = match tokio::time::timeout(PUT_STORM_BOUND, put_task).await {
        Ok(counts) => counts.expect("no panic"),
        Err(_) => panic!(
            "the put storm did not end {PUT_STORM_BOUND:?} after the queries ({:.1} s into the storm)",
            storm.elapsed().as_secs_f64()
        ),
    };
    let storm_time = storm.elapsed();

    // The report.
    let (mut total_queries, mut total_puts, mut failures) = (0, 0, Vec::new());
    for (key, o) in &query_outcomes {
        eprintln!(
            "query {key}: {} sent, {} answered, {} refused, {} failed",
            o.sent,
            o.ok,
            o.refused,
            o.failures.len()
        );
        total_queries += o.sent;
        failures.extend(o.failures.iter().take(5).cloned());
    }
    for (key, n) in &put_counts {
        eprintln!("put {key}: {n}");
        total_puts += n;
    }
    eprintln!(
        "fuzz: {total_queries} queries + {total_puts} puts = {} payloads in {:.1} s (storm {:.1} s)",
        total_queries + total_puts,
        started.elapsed().as_secs_f64(),
        storm_time.as_secs_f64()
    );
    assert!(failures.is_empty(), "failures:\n{}", failures.join("\n"));
    assert_eq!(
        PANICS.load(Ordering::SeqCst),
        0,
        "a service panicked (see the log)"
    );
    assert!(total_queries + total_puts >= 100_000);

    // Every service is still there and answers a normal request.
    for name in [
        roam_map_server::SERVICE_NAME,
        roam_planner::SERVICE_NAME,
        roam_sim::service::SERVICE_NAME,
        roam_localization::service::SERVICE_NAME,
        roam_controller::service::SERVICE_NAME,
        roam_mapper::service::SERVICE_NAME,
    ] {
        assert!(
            harness.is_live(name).await,
            "{name} lost its liveliness token"
        );
    }
    // Give the planner its real map back, above any fuzzed version.
    for mut layer in [inflated, information] {
        layer.version = u64::MAX;
        within(
            "republish",
            session.put(keys::map_layer(&root, &layer.name), encode(&layer)),
        )
        .await
        .expect("put");
    }
    let _: LayerList = within(
        "index after",
        client.request::<LayerList, LayerList>(&keys::map_index(&root), None),
    )
    .await
    .expect("the map server answers after the storm");
    let _: SimStatus = within(
        "sim after",
        client.request(&keys::sim_control(&root), Some(&SimControl::Pause)),
    )
    .await
    .expect("the sim answers after the storm");
    let _: SimStatus = within(
        "sim step after",
        client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 1 })),
    )
    .await
    .expect("the sim steps after the storm");
    let _: PebReply = within(
        "peb after",
        client.request(
            &keys::localization_peb(&root),
            Some(&PebQuery {
                at: PebWhere::Points(vec![[10.0, 16.0]]),
                anchors: None,
                gradient: false,
                crb: false,
            }),
        ),
    )
    .await
    .expect("localization answers after the storm");
    let _: MapperStatus = within(
        "mapper after",
        client.request::<MapperStatus, MapperStatus>(&keys::mapper_status(&root), None),
    )
    .await
    .expect("the mapper answers after the storm");
    // The republished map reaches the planner asynchronously.
    let until = Instant::now() + Duration::from_secs(10);
    loop {
        let plan = client
            .request::<PlanRequest, Plan>(
                &keys::planner_plan(&root),
                Some(&plan_request([-8.0, -8.0], [6.0, -7.0])),
            )
            .await;
        match plan {
            Ok(plan) => {
                assert!(!plan.points.is_empty());
                break;
            }
            Err(e) if Instant::now() < until => {
                eprintln!("plan after the storm not yet: {e}");
                tokio::time::sleep(Duration::from_millis(200)).await;
            }
            Err(e) => panic!("the planner does not plan after the storm: {e}"),
        }
    }

    // The subscribers still work: a step's ranges reach localization, whose estimate
    // reaches the controller, which takes a new mission.
    let estimates = within(
        "subscribe",
        session.declare_subscriber(keys::robot_estimate(&root, "robot")),
    )
    .await
    .expect("subscriber");
    let statuses = within(
        "subscribe",
        session.declare_subscriber(keys::robot_controller(&root, "robot")),
    )
    .await
    .expect("subscriber");
    let mission = Mission {
        after_step: None,
        robot: "robot".into(),
        id: "after-the-storm".into(),
        waypoints: vec![[60.0, 16.0]],
        recovery: false,
    };
    within(
        "mission",
        session.put(keys::robot_mission(&root, "robot"), encode(&mission)),
    )
    .await
    .expect("put");
    let stepped: SimStatus = within(
        "step",
        client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 1 })),
    )
    .await
    .expect("step");
    within("a fresh estimate", async {
        loop {
            let sample = estimates.recv_async().await.expect("sample");
            let e: PositionEstimate = decode(&sample.payload().to_bytes()).expect("estimate");
            if e.step == stepped.step {
                break;
            }
        }
    })
    .await;
    within("the new mission in a controller status", async {
        loop {
            let sample = statuses.recv_async().await.expect("sample");
            let status: roam_proto::controller::ControllerStatus =
                decode(&sample.payload().to_bytes()).expect("status");
            if status.mission.as_deref() == Some("after-the-storm") {
                break;
            }
        }
    })
    .await;
    assert_eq!(
        PANICS.load(Ordering::SeqCst),
        0,
        "a service panicked (see the log)"
    );

    // Nothing panicked: every service stops cleanly.
    for (name, service) in [
        ("mapper", mapper),
        ("controller", controller),
        ("localization", localization),
        ("sim", sim),
        ("planner", planner),
        ("map server", map_server),
    ] {
        let (_, outcome) = service.stop().await;
        assert_eq!(outcome, Ok(()), "{name} did not stop cleanly");
    }
    eprintln!(
        "fuzz: total wall time {:.1} s",
        started.elapsed().as_secs_f64()
    );
    harness.close().await;
}
