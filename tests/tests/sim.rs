//! The sim world through Zenoh: a client loads scenarios, drives a robot, reads its
//! ranges, observations and events, sees a collision refused, replays a seed bit for bit,
//! and gets a structured error for every bad request.

use std::time::Duration;

use roam_proto::sim::{
    GroundTruth, LocalObservation, RangeScan, RobotCommand, RobotEvents, SimClock, SimControl,
    SimStatus,
};
use roam_proto::{decode, encode, keys, ErrorCode, ErrorReply, Message};
use roam_runtime::{ClientError, Requester};
use roam_tests::{within, Harness, RunningService};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

async fn control(
    client: &Requester,
    root: &str,
    request: SimControl,
) -> Result<SimStatus, ClientError> {
    within(
        "sim control",
        client.request(&keys::sim_control(root), Some(&request)),
    )
    .await
}

async fn refused(client: &Requester, root: &str, request: SimControl) -> ErrorReply {
    match control(client, root, request).await {
        Err(ClientError::Refused(reply)) => reply,
        other => panic!("expected a refusal, got {other:?}"),
    }
}

async fn subscribe(client: &Requester, key: String) -> Subscriber<FifoChannelHandler<Sample>> {
    within("subscribe", client.session().declare_subscriber(key))
        .await
        .expect("subscriber")
}

async fn next<T: Message>(subscriber: &Subscriber<FifoChannelHandler<Sample>>) -> T {
    let sample = within("sample", subscriber.recv_async())
        .await
        .expect("sample");
    decode(&sample.payload().to_bytes()).expect("message")
}

fn drain<T: Message>(subscriber: &Subscriber<FifoChannelHandler<Sample>>) -> Vec<T> {
    let mut out = Vec::new();
    while let Ok(Some(sample)) = subscriber.try_recv() {
        out.push(decode(&sample.payload().to_bytes()).expect("message"));
    }
    out
}

async fn command(client: &Requester, root: &str, robot: &str, u: [f64; 2]) {
    within(
        "command",
        client.session().put(
            keys::robot_command(root, robot),
            encode(&RobotCommand { u, step: None }),
        ),
    )
    .await
    .expect("put");
}

async fn boot() -> (Harness, RunningService, Requester) {
    let harness = Harness::start().await;
    let sim = harness.start_role(harness.sim_config(None)).await;
    let client = harness.client().await;
    (harness, sim, client)
}

async fn stop(harness: Harness, sim: RunningService) {
    sim.stop().await.1.expect("sim stops cleanly");
    harness.close().await;
}

/// A shipped scenario, by its name in the sim's load directory (`config/scenarios`,
/// [`Harness::sim_config`]).
fn scenario(name: &str) -> String {
    name.to_owned()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_client_loads_a_scenario_reads_the_sensors_and_sees_a_collision() {
    let (harness, sim, client) = boot().await;
    let root = harness.root.clone();
    let status = control(
        &client,
        &root,
        SimControl::Load {
            path: scenario("es1.yaml"),
            seed: 3,
        },
    )
    .await
    .expect("load es1");
    assert!(!status.running, "a load leaves the sim paused");
    assert_eq!(status.robots.len(), 1);
    assert_eq!(status.anchors.len(), 5);
    let robot = status.robots[0].name.clone();

    let ranges = subscribe(&client, keys::robot_ranges(&root, &robot)).await;
    let observation = subscribe(&client, keys::robot_observation(&root, &robot)).await;
    let truth = subscribe(&client, keys::robot_truth(&root, &robot)).await;
    let clock = subscribe(&client, keys::sim_clock(&root)).await;
    let status = control(&client, &root, SimControl::Step { n: 1 })
        .await
        .expect("step");
    assert_eq!(status.step, 1);
    let scan: RangeScan = next(&ranges).await;
    assert!(
        scan.ranges.len() >= 3,
        "waypoint A is covered by three anchors: {scan:?}"
    );
    for r in &scan.ranges {
        let true_d = (r.at[0] - 10.0).hypot(r.at[1] - 16.0);
        assert!((r.range_m - true_d).abs() < 1.0, "{r:?} vs {true_d}");
    }
    let seen: LocalObservation = next(&observation).await;
    assert!(seen.meta.width > 0 && seen.cells.len() as u64 == seen.meta.cell_count());
    let at: GroundTruth = next(&truth).await;
    assert!((at.at[0] - 10.0).abs() < 0.1 && (at.at[1] - 16.0).abs() < 0.1);
    let tick: SimClock = next(&clock).await;
    assert_eq!(tick.step, 1);

    // The grid world: drive west into the border wall; the move is refused and reported.
    let status = control(
        &client,
        &root,
        SimControl::Load {
            path: scenario("grid004.yaml"),
            seed: 1,
        },
    )
    .await
    .expect("load grid004");
    let robot = status.robots[0].name.clone();
    let events = subscribe(&client, keys::robot_events(&root, &robot)).await;
    let truth = subscribe(&client, keys::robot_truth(&root, &robot)).await;
    let mut collision = None;
    for _ in 0..16 {
        command(&client, &root, &robot, [-1.0, 0.0]).await;
        control(&client, &root, SimControl::Step { n: 1 })
            .await
            .expect("step");
        if let Some(e) = drain::<RobotEvents>(&events).into_iter().find(|e| {
            e.events
                .iter()
                .any(|k| matches!(k, roam_proto::sim::RobotEventKind::Collision { .. }))
        }) {
            collision = Some(e);
            break;
        }
    }
    let collision = collision.expect("a collision with the west wall");
    let positions: Vec<GroundTruth> = drain(&truth);
    let last = positions.last().expect("truth");
    assert!(
        last.at[0] > -12.0,
        "the robot never enters the wall: {last:?}"
    );
    assert!(!collision.events.is_empty());
    stop(harness, sim).await;
}

/// Runs 30 steps of es1 with seed 7 and fixed commands, returning every range bit.
async fn replay(client: &Requester, root: &str) -> Vec<u64> {
    control(client, root, SimControl::Reset { seed: 7 })
        .await
        .expect("reset");
    let ranges = subscribe(client, keys::robot_ranges(root, "robot")).await;
    let mut bits = Vec::new();
    for k in 0..30 {
        command(
            client,
            root,
            "robot",
            [1.0, if k % 2 == 0 { 0.5 } else { -0.5 }],
        )
        .await;
        control(client, root, SimControl::Step { n: 1 })
            .await
            .expect("step");
        let scan: RangeScan = next(&ranges).await;
        bits.extend(scan.ranges.iter().map(|r| r.range_m.to_bits()));
    }
    bits
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_same_seed_gives_the_same_sensor_stream_bit_for_bit() {
    let (harness, sim, client) = boot().await;
    let root = harness.root.clone();
    control(
        &client,
        &root,
        SimControl::Load {
            path: scenario("es1.yaml"),
            seed: 7,
        },
    )
    .await
    .expect("load");
    let first = replay(&client, &root).await;
    let second = replay(&client, &root).await;
    assert!(!first.is_empty());
    assert_eq!(first, second);
    stop(harness, sim).await;

    // And after a restart of the service.
    let (harness, sim, client) = boot().await;
    let root = harness.root.clone();
    control(
        &client,
        &root,
        SimControl::Load {
            path: scenario("es1.yaml"),
            seed: 7,
        },
    )
    .await
    .expect("load");
    assert_eq!(replay(&client, &root).await, first);
    stop(harness, sim).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn free_running_publishes_the_clock_and_pauses() {
    let (harness, sim, client) = boot().await;
    let root = harness.root.clone();
    let clock = subscribe(&client, keys::sim_clock(&root)).await;
    let status = control(&client, &root, SimControl::Resume { rate: 0.0 })
        .await
        .expect("resume");
    assert!(status.running);
    let a: SimClock = next(&clock).await;
    let b: SimClock = next(&clock).await;
    assert!(b.step > a.step && b.time_s > a.time_s);
    let paused = control(&client, &root, SimControl::Pause)
        .await
        .expect("pause");
    assert!(!paused.running);
    tokio::time::sleep(Duration::from_millis(100)).await;
    let _ = drain::<SimClock>(&clock);
    let later = control(&client, &root, SimControl::Status)
        .await
        .expect("status");
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert_eq!(
        control(&client, &root, SimControl::Status)
            .await
            .expect("status")
            .step,
        later.step,
        "paused means no steps"
    );
    stop(harness, sim).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn bad_requests_get_errors_that_name_what_to_fix() {
    let harness = Harness::start().await;
    let dir = tempfile::tempdir().expect("tmp");
    let mut config = harness.sim_config(None);
    config.load_dirs.push(dir.path().to_owned());
    let sim = harness.start_role(config).await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let missing = refused(
        &client,
        &root,
        SimControl::Load {
            path: "/nonexistent/world.yaml".into(),
            seed: 0,
        },
    )
    .await;
    assert_eq!(missing.code, ErrorCode::NotFound);
    assert!(missing.message.contains("/nonexistent/world.yaml"));
    assert!(
        missing.message.contains("load directories"),
        "{}",
        missing.message
    );

    // A scenario in the load directory that is invalid names the file and the field.
    std::fs::write(dir.path().join("bad.yaml"), "name: bad\nmap: {grid: {size_m: [10, 10], resolution: 0.5}}\nrobots:\n  - { name: r, at: [50.0, 1.0] }\n").expect("write");
    let invalid = refused(
        &client,
        &root,
        SimControl::Load {
            path: "bad.yaml".into(),
            seed: 0,
        },
    )
    .await;
    assert_eq!(invalid.code, ErrorCode::InvalidRequest);
    assert!(
        invalid.message.contains("bad.yaml") && invalid.message.contains("robots[0]"),
        "{}",
        invalid.message
    );
    // Neither a reply nor the status names where the sim keeps its scenarios.
    let folders = [
        dir.path().display().to_string(),
        dir.path().canonicalize().expect("c").display().to_string(),
    ];
    for message in [&missing.message, &invalid.message] {
        assert!(
            folders.iter().all(|f| !message.contains(f.as_str())),
            "{message}"
        );
    }

    let too_many = refused(&client, &root, SimControl::Step { n: 1_000_000 }).await;
    assert_eq!(
        too_many.limit.map(|l| l.name),
        Some("max_steps_per_request".to_owned())
    );
    let in_wall = refused(
        &client,
        &root,
        SimControl::AddRobot {
            name: "r2".into(),
            at: [-9.95, 0.0],
        },
    )
    .await;
    assert_eq!(in_wall.code, ErrorCode::InvalidRequest);
    let unknown = refused(
        &client,
        &root,
        SimControl::RemoveRobot {
            name: "ghost".into(),
        },
    )
    .await;
    assert_eq!(unknown.code, ErrorCode::NotFound);
    let rate = refused(&client, &root, SimControl::Resume { rate: -1.0 }).await;
    assert!(rate.message.contains("rate"));
    control(&client, &root, SimControl::Resume { rate: 1.0 })
        .await
        .expect("resume");
    let racing = refused(&client, &root, SimControl::Step { n: 1 }).await;
    assert!(racing.message.contains("pause"), "{}", racing.message);

    let added = control(
        &client,
        &root,
        SimControl::AddRobot {
            name: "r2".into(),
            at: [0.5, 0.5],
        },
    )
    .await
    .expect("add");
    assert!(added.robots.iter().any(|r| r.name == "r2"));
    let removed = control(
        &client,
        &root,
        SimControl::RemoveRobot { name: "r2".into() },
    )
    .await
    .expect("remove");
    assert!(!removed.robots.iter().any(|r| r.name == "r2"));

    let malformed = match within(
        "raw",
        client.request_raw::<SimStatus>(&keys::sim_control(&root), Some(b"{\"v\":1}".to_vec())),
    )
    .await
    {
        Err(ClientError::Refused(r)) => r,
        other => panic!("{other:?}"),
    };
    assert_eq!(malformed.code, ErrorCode::Malformed);
    // A scenario in the load directory loads, and the status names it by its file.
    std::fs::copy(
        roam_tests::repo_path("config/scenarios/grid004.yaml"),
        dir.path().join("good.yaml"),
    )
    .expect("copy");
    let loaded = control(
        &client,
        &root,
        SimControl::Load {
            path: "good.yaml".into(),
            seed: 0,
        },
    )
    .await
    .expect("a scenario in the load directory loads");
    assert_eq!(loaded.scenario, "good.yaml");
    stop(harness, sim).await;
}

/// The sim's status tells any peer which scenario runs by its file name, never by where
/// it lies on the sim's machine (here an absolute path from the config).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_status_names_the_scenario_file_not_its_path() {
    let harness = Harness::start().await;
    let config = harness.sim_config(Some("config/scenarios/es1.yaml"));
    let configured = config.scenario.clone().expect("a scenario");
    assert!(configured.is_absolute(), "{}", configured.display());
    let sim = harness.start_role(config).await;
    let client = harness.client().await;
    let status = control(&client, &harness.root, SimControl::Status)
        .await
        .expect("status");
    assert_eq!(status.scenario, "es1.yaml");
    stop(harness, sim).await;
}

/// The semi-static objects on `sim/objects` are the sim's own, message for message: the
/// warehouse (its robots taken out, so nothing but the zones' stream decides) stepped
/// 2,000 times in lock-step through the service sends one message in each step where an
/// object landed or left, listing what an in-process `Sim` of the same scenario and seed
/// has landed in that step (`semi_static::landed_truth`), and nothing in the others.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_objects_on_the_wire_are_the_sims_own() {
    const STEPS: u32 = 2000;
    let harness = Harness::start().await;
    let path = "config/scenarios/warehouse.yaml";
    let sim = harness.start_role(harness.sim_config(Some(path))).await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let scenario =
        roam_world::scenario::load(&roam_tests::repo_path(path), roam_world::DEFAULT_MAX_CELLS)
            .expect("the warehouse loads");
    let mut local = roam_sim::sim::Sim::new(&scenario, 0).expect("sim");
    for robot in &scenario.file.robots {
        control(
            &client,
            &root,
            SimControl::RemoveRobot {
                name: robot.name.clone(),
            },
        )
        .await
        .expect("the robot leaves");
        local.remove_robot(&robot.name).expect("the robot leaves");
    }
    let objects = subscribe(&client, keys::sim_objects(&root)).await;
    control(&client, &root, SimControl::Step { n: STEPS })
        .await
        .expect("steps");
    let mut expected = Vec::new();
    let mut before: Vec<u64> = Vec::new();
    for _ in 0..STEPS {
        let report = local.step(&[]).expect("a step");
        let landed = roam_sim::semi_static::landed_truth(local.world().objects());
        let ids: Vec<u64> = landed.iter().map(|o| o.id).collect();
        if ids != before {
            expected.push((report.step, landed));
            before = ids;
        }
    }
    assert!(
        expected.len() >= 2,
        "the warehouse's zones land and clear objects within {STEPS} steps"
    );
    let mut heard = Vec::new();
    for _ in 0..expected.len() {
        let m: roam_proto::sim::ObjectsTruth = next(&objects).await;
        heard.push((m.step, m.objects));
    }
    assert_eq!(heard, expected);
    tokio::time::sleep(Duration::from_millis(200)).await;
    assert!(drain::<roam_proto::sim::ObjectsTruth>(&objects).is_empty());
    stop(harness, sim).await;
}
