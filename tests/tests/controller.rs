//! The APF controller through Zenoh with the sim world and localization: an ES1 mission
//! in lock-step drives the same trajectory as the batch run with the same seed; stale
//! estimates halt the robot within the configured time; a local minimum is reported.

use std::time::{Duration, Instant};

use roam_controller::params::ApfParams;
use roam_controller::service::ControllerConfig;
use roam_controller::weights::Scheme;
use roam_proto::controller::{ControllerStatus, Mission, MissionState};
use roam_proto::localization::PositionEstimate;
use roam_proto::sim::{GroundTruth, RobotCommand, SimControl, SimStatus};
use roam_proto::{decode, encode, keys, Message};
use roam_tests::{repo_path, within, Harness};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

type Sub = Subscriber<FifoChannelHandler<Sample>>;

async fn subscribe(client: &roam_runtime::Requester, key: String) -> Sub {
    within("subscribe", client.session().declare_subscriber(key))
        .await
        .expect("subscriber")
}

async fn next<T: Message>(sub: &Sub) -> T {
    let sample = within("a sample", sub.recv_async()).await.expect("sample");
    decode(&sample.payload().to_bytes()).expect("decodes")
}

async fn put<T: Message>(client: &roam_runtime::Requester, key: String, message: &T) {
    within("put", client.session().put(key, encode(message)))
        .await
        .expect("put");
}

/// Puts a one-waypoint mission for the robot `robot`, as a mission executive would.
async fn give_mission(client: &roam_runtime::Requester, root: &str, id: &str, to: [f64; 2]) {
    let mission = Mission {
        robot: "robot".into(),
        id: id.into(),
        waypoints: vec![to],
    };
    put(client, keys::robot_mission(root, "robot"), &mission).await;
}

/// Waits for the controller status of a mission that satisfies `done`.
async fn status_until(
    statuses: &Sub,
    deadline: Duration,
    done: impl Fn(&ControllerStatus) -> bool,
) -> ControllerStatus {
    let until = Instant::now() + deadline;
    loop {
        let left = until.saturating_duration_since(Instant::now());
        let sample = tokio::time::timeout(left, statuses.recv_async())
            .await
            .unwrap_or_else(|_| panic!("no matching controller status within {deadline:?}"))
            .expect("sample");
        let status: ControllerStatus = decode(&sample.payload().to_bytes()).expect("status");
        if done(&status) {
            return status;
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn an_es1_mission_through_zenoh_drives_the_batch_trajectory() {
    const SEED: u64 = 11;
    let scenario = "config/scenarios/es1.yaml";
    let params = ApfParams {
        scheme: Scheme::Linear,
        ..ApfParams::default()
    };
    let batch = roam_controller::episode::es1_mission(&repo_path(scenario), &params, SEED)
        .expect("batch episode");
    let expected = &batch.robots[0];
    assert!(expected.success, "the linear scheme reaches B in batch");

    let harness = Harness::start().await;
    let mut sim_config = harness.sim_config(Some(scenario));
    sim_config.seed = SEED;
    let _sim = harness.start_sim(sim_config).await;
    let _localization = harness.start_localization(Some(scenario)).await;
    let _controller = harness
        .start_controller(ControllerConfig {
            scenario: Some(repo_path(scenario)),
            // Lock-step waits on this test, not on the clock: no stale halts.
            stale_after_s: 60.0,
            apf: params.clone(),
            ..harness.controller_config()
        })
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let commands = subscribe(&client, keys::robot_command(&root, "robot")).await;
    let truth = subscribe(&client, keys::robot_truth(&root, "robot")).await;
    let statuses = subscribe(&client, keys::robot_controller(&root, "robot")).await;
    give_mission(&client, &root, "es1", [60.0, 16.0]).await;
    status_until(&statuses, Duration::from_secs(10), |s| {
        s.mission.as_deref() == Some("es1")
    })
    .await;

    let mut driven = Vec::new();
    let mut last_state = MissionState::Active;
    for step in 1..=expected.truth.len() as u64 {
        let _: SimStatus = within(
            "step",
            client.request(&keys::sim_control(&root), Some(&SimControl::Step { n: 1 })),
        )
        .await
        .expect("step");
        let at: GroundTruth = next(&truth).await;
        assert_eq!(at.step, step);
        driven.push(at.at);
        let status = status_until(&statuses, Duration::from_secs(10), |s| {
            s.estimate_step == Some(step)
        })
        .await;
        last_state = status.state;
        if status.state == MissionState::Active {
            // The command for this step has left the controller; the next step takes it.
            loop {
                let command: RobotCommand = next(&commands).await;
                if command.step == Some(step) {
                    break;
                }
            }
        }
    }
    assert_eq!(
        last_state,
        MissionState::Completed,
        "B reached through Zenoh"
    );
    assert_eq!(driven.len(), expected.truth.len());
    for (k, (ours, batch)) in driven.iter().zip(&expected.truth).enumerate() {
        assert_eq!(ours, batch, "step {}: services and batch part", k + 1);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn stale_estimates_halt_the_robot_within_the_configured_time() {
    let scenario = "config/scenarios/es2.yaml";
    let harness = Harness::start().await;
    let mut sim_config = harness.sim_config(Some(scenario));
    sim_config.rate = Some(10.0); // 25 steps per second
    let _sim = harness.start_sim(sim_config).await;
    let localization = harness.start_localization(Some(scenario)).await;
    let stale_after_s = 0.5;
    let _controller = harness
        .start_controller(ControllerConfig {
            scenario: Some(repo_path(scenario)),
            stale_after_s,
            ..harness.controller_config()
        })
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let statuses = subscribe(&client, keys::robot_controller(&root, "robot")).await;
    let truth = subscribe(&client, keys::robot_truth(&root, "robot")).await;
    give_mission(&client, &root, "far", [45.0, 45.0]).await;
    status_until(&statuses, Duration::from_secs(10), |s| {
        s.state == MissionState::Active && s.steps >= 10
    })
    .await;

    let stopped = Instant::now();
    localization.stop().await.1.expect("clean stop");
    let halted = status_until(&statuses, Duration::from_secs(5), |s| {
        s.state == MissionState::HaltedStale
    })
    .await;
    let after = stopped.elapsed();
    assert!(
        after <= Duration::from_secs_f64(stale_after_s) + Duration::from_millis(400),
        "halted {after:?} after the last estimate could have come (configured {stale_after_s} s)"
    );
    assert_eq!(halted.u, [0.0, 0.0]);
    // Held: the robot no longer moves.
    while truth.try_recv().ok().flatten().is_some() {}
    let first: GroundTruth = next(&truth).await;
    for _ in 0..10 {
        let later: GroundTruth = next(&truth).await;
        assert_eq!(later.at, first.at, "the robot moved while halted");
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_local_minimum_is_reported_as_stuck() {
    let scenario = "config/scenarios/trap.yaml";
    let harness = Harness::start().await;
    let mut sim_config = harness.sim_config(Some(scenario));
    sim_config.rate = Some(0.0); // as fast as the services keep up
    let _sim = harness.start_sim(sim_config).await;
    let _localization = harness.start_localization(Some(scenario)).await;
    let _controller = harness
        .start_controller(ControllerConfig {
            scenario: Some(repo_path(scenario)),
            stale_after_s: 5.0,
            apf: ApfParams {
                scheme: Scheme::Plain,
                stuck_window_steps: 60,
                ..ApfParams::default()
            },
            ..harness.controller_config()
        })
        .await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let statuses = subscribe(&client, keys::robot_controller(&root, "robot")).await;
    give_mission(&client, &root, "through the wall", [25.0, 10.0]).await;
    let stuck = status_until(&statuses, Duration::from_secs(60), |s| {
        matches!(
            s.state,
            MissionState::Stuck | MissionState::Completed | MissionState::StepLimit
        )
    })
    .await;
    assert_eq!(stuck.state, MissionState::Stuck, "{stuck:?}");
    // Stuck in front of the U's back wall, well short of the waypoint.
    assert!(
        stuck.distance_left_m.expect("distance") > 9.0,
        "stuck {:?} m from the waypoint",
        stuck.distance_left_m
    );
    let _: SimStatus = within(
        "pause",
        client.request(&keys::sim_control(&root), Some(&SimControl::Pause)),
    )
    .await
    .expect("pause");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_controller_on_board_one_robot_leaves_the_others_alone() {
    let scenario = "config/scenarios/es2.yaml";
    let harness = Harness::start().await;
    let mut sim_config = harness.sim_config(Some(scenario));
    sim_config.rate = Some(10.0);
    let _sim = harness.start_sim(sim_config).await;
    let _localization = harness.start_localization(Some(scenario)).await;
    let on_board = |robot: &str| ControllerConfig {
        scenario: Some(repo_path(scenario)),
        robots: vec![robot.to_owned()],
        instance: Some(format!("on-{robot}")),
        ..harness.controller_config()
    };
    let other = harness.start_controller(on_board("other")).await;
    let client = harness.client().await;
    let root = harness.root.clone();
    let statuses = subscribe(&client, keys::robot_controller(&root, "robot")).await;
    let commands = subscribe(&client, keys::robot_command(&root, "robot")).await;
    let estimates = subscribe(&client, keys::robot_estimate(&root, "robot")).await;
    give_mission(&client, &root, "not-yours", [45.0, 45.0]).await;
    // Ten estimates of the robot after the mission: a controller that took it would
    // have commanded on them.
    for _ in 0..10 {
        let _: PositionEstimate = next(&estimates).await;
    }
    assert!(
        statuses.try_recv().ok().flatten().is_none()
            && commands.try_recv().ok().flatten().is_none(),
        "a controller on board 'other' took robot's mission"
    );
    other.stop().await.1.expect("clean stop");

    let _mine = harness.start_controller(on_board("robot")).await;
    give_mission(&client, &root, "yours", [45.0, 45.0]).await;
    let status = status_until(&statuses, Duration::from_secs(10), |s| {
        s.state == MissionState::Active && s.steps >= 5
    })
    .await;
    assert_eq!(status.mission.as_deref(), Some("yours"));
    let _: RobotCommand = next(&commands).await;
}
