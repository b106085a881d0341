//! The downtime mission through Zenoh: the map server, the planner, the sim (faster than
//! real time), localization, the controller and the mission executive as separate
//! services on loopback; the executive's window reports say the robot was on time at
//! both tasks and gathered more information than the shortest paths would have, and,
//! with no planner on the bus, that it drove its own fastest paths on time.

use std::time::Duration;

use roam_controller::service::ControllerConfig;
use roam_mission::calibration::TimeModel;
use roam_mission::executive::ExecutiveConfig;
use roam_mission::service::MissionConfig;
use roam_planner::config::PlannerConfig;
use roam_proto::mission::WindowReport;
use roam_proto::{decode, keys};
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::Requester;
use roam_tests::{within, Harness, RunningService};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

type Reports = Subscriber<FifoChannelHandler<Sample>>;

/// The roles a test started, kept running while it holds them, and the client session
/// its subscriber lives on.
type Running = (Vec<RunningService>, Requester);

/// Every role of the built-in day but the executive (the planner only if `planner`),
/// the sim at 10x, and a subscriber to the robot's window reports.
async fn roles_of_the_day(harness: &Harness, planner: bool) -> (Running, Reports) {
    let planner = planner.then(|| harness.planner_config("planner-0"));
    roles_of_the_day_with(harness, planner).await
}

/// [`roles_of_the_day`] with this planner, if any.
async fn roles_of_the_day_with(
    harness: &Harness,
    planner: Option<PlannerConfig>,
) -> (Running, Reports) {
    let mut roles = vec![harness.start_role(harness.map_server_config()).await];
    if let Some(planner) = planner {
        roles.push(harness.start_role(planner).await);
    }
    let mut sim_config = harness.sim_config(None);
    sim_config.rate = Some(10.0);
    roles.push(harness.start_role(sim_config).await);
    roles.push(harness.start_role(harness.localization_config(None)).await);
    let controller = ControllerConfig {
        apf: roam::demo::indoor_apf(),
        ..harness.controller_config()
    };
    roles.push(harness.start_role(controller).await);
    let client = harness.client().await;
    let key = keys::robot_mission_report(&harness.root, "robot");
    let reports = within("subscribe", client.session().declare_subscriber(key))
        .await
        .expect("subscriber");
    ((roles, client), reports)
}

/// The next window report, within `seconds`.
type Missions = Subscriber<FifoChannelHandler<Sample>>;

/// A subscriber to the robot's missions, on the client's session.
async fn missions_of(harness: &Harness, client: &Requester) -> Missions {
    within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::robot_mission(&harness.root, "robot")),
    )
    .await
    .expect("subscriber")
}

/// The next mission sent, within a minute.
async fn next_mission(missions: &Missions) -> roam_proto::controller::Mission {
    let sample = tokio::time::timeout(Duration::from_secs(60), missions.recv_async())
        .await
        .expect("a mission in time")
        .expect("sample");
    decode(&sample.payload().to_bytes()).expect("mission")
}

async fn next_report(reports: &Reports, seconds: u64) -> WindowReport {
    let sample = tokio::time::timeout(Duration::from_secs(seconds), reports.recv_async())
        .await
        .expect("a window report in time")
        .expect("sample");
    decode(&sample.payload().to_bytes()).expect("report")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn the_demo_mission_is_on_time_and_more_curious_than_the_shortest_path() {
    let harness = Harness::start().await;
    let (_roles, reports) = roles_of_the_day(&harness, true).await;
    let _mission = harness
        .start_role(MissionConfig {
            service: ServiceConfig::at(harness.root.clone()),
            executive: ExecutiveConfig {
                // A pessimistic prior (a stale datasheet: the robot drives a metre in
                // 2 s, the executive believes 3 s), so the first window's plan would
                // arrive early: the slack rule must fire.
                time_model_prior: TimeModel {
                    v_lin: 3.0,
                    v_ang: 1.0,
                },
                ..ExecutiveConfig::default()
            },
            ..MissionConfig::default()
        })
        .await;

    // Two windows of 75 s and 90 s of sim time at 10x: about 17 s.
    let mut windows = Vec::new();
    for _ in 0..2 {
        windows.push(next_report(&reports, 60).await);
    }
    assert_eq!(
        windows.iter().map(|w| w.task.as_str()).collect::<Vec<_>>(),
        ["goal1", "goal2"]
    );
    // The first window is planned with the pessimistic prior: the robot would arrive
    // early, so the slack rule replans a curious path with the time left, and the robot
    // is still on time.
    assert!(
        windows
            .iter()
            .any(|w| w.replan_reasons.iter().any(|r| r.starts_with("slack"))),
        "no slack replan: {windows:?}"
    );
    for w in &windows {
        assert!(w.on_time, "late at {}: {w:?}", w.task);
        assert!(w.peb_mean_m.is_some_and(|p| p < 0.5), "{w:?}");
    }
    let driven: f64 = windows.iter().map(|w| w.driven_information).sum();
    let shortest: f64 = windows.iter().map(|w| w.shortest_information).sum();
    assert!(
        driven > shortest,
        "driven {driven} against the shortest paths' {shortest}"
    );
}

/// Degrade, don't stop: with no planner on the bus, the executive drives the fastest
/// path it computes itself (on the map it fetched), says so in its reports, and is on
/// time at both tasks.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn without_a_planner_the_executive_drives_its_own_fastest_path_on_time() {
    let harness = Harness::start().await;
    let (_roles, reports) = roles_of_the_day(&harness, false).await;
    let _mission = harness
        .start_role(MissionConfig {
            service: ServiceConfig::at(harness.root.clone()),
            ..MissionConfig::default()
        })
        .await;
    let mut windows = Vec::new();
    for _ in 0..2 {
        windows.push(next_report(&reports, 90).await);
    }
    assert_eq!(
        windows.iter().map(|w| w.task.as_str()).collect::<Vec<_>>(),
        ["goal1", "goal2"]
    );
    for w in &windows {
        assert!(
            w.on_time && w.arrival_s.is_some(),
            "late at {}: {w:?}",
            w.task
        );
        // It says why it drove what it drove: no planner answered.
        assert!(w.replan_reasons.iter().any(|r| r == "no_planner"), "{w:?}");
        // What it planned is the fastest path's information: no curious plan came.
        assert_eq!(w.planned_information, w.shortest_information, "{w:?}");
    }
}

/// A restarted executive picks up its robot's time calibration: the first executive
/// saves its fit after its first arrival and is stopped; its successor, started with the
/// same `calibration_file`, plans the next window with that fit, not with the prior.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_restarted_executive_plans_with_the_fit_its_predecessor_saved() {
    let harness = Harness::start().await;
    let (_roles, reports) = roles_of_the_day(&harness, true).await;
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("robot.calibration.json");
    let config = MissionConfig {
        service: ServiceConfig::at(harness.root.clone()),
        executive: ExecutiveConfig {
            calibration_file: Some(file.clone()),
            ..ExecutiveConfig::default()
        },
        ..MissionConfig::default()
    };
    let first = harness.start_role(config.clone()).await;
    let goal1 = next_report(&reports, 90).await;
    assert_eq!(goal1.task, "goal1");
    let (_, stopped) = first.stop().await;
    stopped.expect("the first executive stops cleanly");

    let prior = ExecutiveConfig::default().time_model_prior;
    let (saved, _) = roam_mission::calibration::store::load(
        &file,
        "robot",
        prior,
        roam_mission::calibration::CalibrationConfig::default(),
    )
    .expect("the first executive saved its fit");
    let saved = saved.model();
    assert_ne!(
        saved, prior,
        "the fit learned nothing from the first window"
    );

    let _second = harness.start_role(config).await;
    // The successor may report the task it was restarted in first (late: its arrival is
    // the restart's time); the window after it is planned with the restored fit.
    let goal2 = loop {
        let report = next_report(&reports, 90).await;
        if report.task == "goal2" {
            break report;
        }
    };
    let planned_with = goal2.time_model.as_ref().expect("a time model");
    assert_eq!(
        (planned_with.v_lin, planned_with.v_ang),
        (saved.v_lin, saved.v_ang),
        "goal2 planned with {planned_with:?}, the saved fit is {saved:?}"
    );
}

/// The map changes under the route: while the robot drives its first window's curious
/// route, a client (standing in for the mapper) writes an `occupied_now` layer with a
/// pallet on the route ahead. The executive, following that layer, replans at once
/// (`map_changed`); the planner, planning round the same layer, sends a route that
/// keeps clear of the pallet; and the robot is still on time.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_pallet_seen_on_the_route_ahead_is_a_replan_round_it() {
    use roam_proto::cells::Cells;
    use roam_proto::controller::Mission;
    use roam_proto::map::{Layer, LayerChange, LayerUpdate, UpdateAck, INFLATED_LAYER};
    use roam_proto::mapper::OCCUPIED_NOW_LAYER;

    const PALLET_M: f64 = 0.3;
    let harness = Harness::start().await;
    let planner = PlannerConfig {
        obstacles_layer: Some(OCCUPIED_NOW_LAYER.to_owned()),
        ..harness.planner_config("planner-0")
    };
    let ((_roles, client), reports) = roles_of_the_day_with(&harness, Some(planner)).await;
    let missions = missions_of(&harness, &client).await;
    let _mission = harness
        .start_role(MissionConfig {
            service: ServiceConfig::at(harness.root.clone()),
            executive: ExecutiveConfig {
                obstacles_layer: Some(OCCUPIED_NOW_LAYER.to_owned()),
                ..ExecutiveConfig::default()
            },
            ..MissionConfig::default()
        })
        .await;
    // The window sets off on its fastest path, then takes the curious route.
    let _fastest = next_mission(&missions).await;
    let curious = next_mission(&missions).await;
    let waypoints = &curious.waypoints;
    assert!(waypoints.len() >= 6, "{curious:?}");
    let pallet = waypoints[waypoints.len() * 2 / 3];

    // The static map, and on it the pallet: the cells within PALLET_M of it.
    let inflated: Layer = client
        .request::<Layer, Layer>(&keys::map_layer(&harness.root, INFLATED_LAYER), None)
        .await
        .expect("the inflated layer");
    let Cells::I8(mut cells) = inflated.cells.clone() else {
        panic!("inflated is not i8");
    };
    let meta = inflated.meta;
    for (i, cell) in cells.iter_mut().enumerate() {
        let (x, y) =
            roam_world::grid::cell_center(&meta, i % meta.width as usize, i / meta.width as usize);
        if (x - pallet[0]).hypot(y - pallet[1]) <= PALLET_M {
            *cell = 100;
        }
    }
    let update = LayerUpdate {
        base_version: 0,
        change: LayerChange::Replace {
            meta,
            cells: Cells::I8(cells),
        },
        world: None,
    };
    let _ack: UpdateAck = client
        .request(
            &keys::map_update(&harness.root, OCCUPIED_NOW_LAYER),
            Some(&update),
        )
        .await
        .expect("the occupied_now layer is written");

    // The next route keeps clear of the pallet (the planner blocks PALLET_M round
    // each of its cells, 0.3 m by default). Unless it answers a replan asked before the
    // planner had the layer (a slack replan in flight): then the executive checks that
    // route when it comes, and the one after it is the map change's.
    let nearest = |m: &Mission| roam_mission::path::off_path_m(pallet, &m.waypoints);
    let mut round = next_mission(&missions).await;
    if nearest(&round) <= PALLET_M {
        round = next_mission(&missions).await;
    }
    assert!(
        nearest(&round) > PALLET_M,
        "the route after the map change passes {:.2} m from the pallet: {round:?}",
        nearest(&round)
    );
    let goal1 = next_report(&reports, 90).await;
    assert_eq!(goal1.task, "goal1");
    assert!(
        goal1.replan_reasons.iter().any(|r| r == "map_changed"),
        "{goal1:?}"
    );
    assert!(goal1.on_time, "{goal1:?}");
}

/// A restarted executive drives on with its predecessor's route: the first executive,
/// keeping its route in `resume_file`, is stopped while the robot drives its first
/// window's curious route; its successor, started with the same file, sends the rest of
/// that route (every waypoint on it) as its first mission, not a fastest path of its
/// own, and the window is reported `resumed` and on time.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_restarted_executive_drives_on_with_its_predecessors_route() {
    use roam_proto::controller::Mission;

    let harness = Harness::start().await;
    let ((_roles, client), reports) = roles_of_the_day(&harness, true).await;
    let missions = missions_of(&harness, &client).await;
    let dir = tempfile::tempdir().expect("temp dir");
    let config = MissionConfig {
        service: ServiceConfig::at(harness.root.clone()),
        executive: ExecutiveConfig {
            resume_file: Some(dir.path().join("robot.resume.json")),
            ..ExecutiveConfig::default()
        },
        ..MissionConfig::default()
    };
    let first = harness.start_role(config.clone()).await;
    // The window sets off on its fastest path, then takes the curious route; the robot
    // drives it a while before its executive stops.
    let _fastest = next_mission(&missions).await;
    let _curious = next_mission(&missions).await;
    tokio::time::sleep(Duration::from_secs(1)).await;
    let (_, stopped) = first.stop().await;
    stopped.expect("the first executive stops cleanly");
    // The predecessor's last route: the last mission it sent.
    let mut last = None;
    while let Ok(Some(sample)) = missions.try_recv() {
        last = Some(decode::<Mission>(&sample.payload().to_bytes()).expect("mission"));
    }
    let last = match last {
        Some(m) => m,
        None => _curious,
    };

    let _second = harness.start_role(config).await;
    let resumed = next_mission(&missions).await;
    assert_ne!(resumed.id, last.id);
    for p in &resumed.waypoints {
        let off = roam_mission::path::off_path_m(*p, &last.waypoints);
        assert!(
            off < 0.05,
            "the successor's waypoint {p:?} is {off:.2} m off its predecessor's route"
        );
    }
    let goal1 = next_report(&reports, 90).await;
    assert_eq!(goal1.task, "goal1");
    assert!(
        goal1.replan_reasons.iter().any(|r| r == "resumed"),
        "{goal1:?}"
    );
    assert!(goal1.on_time, "{goal1:?}");
}
