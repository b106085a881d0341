//! A robot on Nav2 driven by roam: `roam mission` plans and watches its day, `roam
//! ros2` (`nav2_robots`, `clock`) turns its poses into roam's estimates and roam's
//! missions into its FollowPath goals. The robot is `tests/clients/python/ros2_client.py
//! fake-nav2-robot`, written from the specs with PyPI's `eclipse-zenoh` and `rosbags`
//! (no roam code): `/clock` at 10× wall time, `/amcl_pose` with a covariance, and a
//! FollowPath action server that drives the pose along each path at a set speed.
//!
//! Needs `python3` with `eclipse-zenoh==1.10.2` and `rosbags==0.11.9`. Without them the
//! tests print a notice and pass, except in CI (`CI` set), where they fail.

mod clients;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use clients::{python_has, run_python, RoamProcess, ScriptRun};
use roam_proto::controller::{ControllerStatus, Mission, MissionState};
use roam_proto::keys;
use roam_proto::localization::PositionEstimate;
use roam_proto::mission::WindowReport;
use roam_runtime::SessionArgs;
use roam_stack::router::free_loopback_port;

/// How close the fitted v_lin must come to the robot's, where Table I's prior (2 s/m)
/// is 20% off. Measured on this 2-core machine: +0.3% to +1.7% over four days, −1.4%
/// and +1.6% with both cores kept busy. The fit holds this close because every drive
/// of a window teaches it, timed by the estimates' own times, and routes that start
/// where a moving robot was do not (`roam_mission::window`, drove.rs): such a robot
/// drives on along its old route while the mission travels, seconds at this clock.
const V_LIN_TOLERANCE: f64 = 0.05;

/// The fake robot's speed, m/s of simulated time, and its clock's rate.
const SPEED_M_PER_S: f64 = 0.6;
const RATE: &str = "10";

fn script() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/clients/python/ros2_client.py")
}

fn repo(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(relative)
}

fn fake_robot(endpoint: &str, until_s: &str, extra: &[&str]) -> ScriptRun {
    let mut args = vec![
        "fake-nav2-robot",
        "--connect",
        endpoint,
        "--speed",
        "0.6",
        "--rate",
        RATE,
        "--until-s",
        until_s,
    ];
    args.extend_from_slice(extra);
    run_python(&script(), &args, Duration::from_secs(300))
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write config");
    path.to_str().expect("utf-8").to_owned()
}

/// A callback keeping each message of type `T` heard in `store`.
fn keep<T: roam_proto::Message + Send + 'static>(
    store: Arc<Mutex<Vec<T>>>,
) -> impl Fn(zenoh::sample::Sample) + Send + Sync + 'static {
    move |sample| {
        if let Ok(m) = roam_proto::decode(&sample.payload().to_bytes()) {
            store.lock().expect("lock").push(m);
        }
    }
}

fn has_python(test: &str) -> bool {
    python_has(
        "zenoh, zenoh.ext, rosbags",
        test,
        "eclipse-zenoh==1.10.2 rosbags==0.11.9",
    )
}

/// The router, the map server on the day world, and the ROS 2 node driving robot `nav`
/// (`answer_timeout_s` and `pose_timeout_s` short for the refusal cases).
fn site(dir: &Path, endpoint: &str, root: &str) -> Vec<RoamProcess> {
    let client = ["--mode", "client", "--connect", endpoint];
    let map_server = write(
        dir,
        "map-server.yaml",
        &format!("map: {}\n", repo("config/scenarios/day.yaml").display()),
    );
    let ros2 = write(
        dir,
        "ros2.yaml",
        "clock: /clock\nnav2_robots:\n  - { robot: nav, answer_timeout_s: 1.0, pose_timeout_s: 1.0 }\n",
    );
    let router = RoamProcess::start(&["router", "--listen", endpoint], root, "router running");
    let mut map_args = vec!["map-server", "--config", &map_server];
    map_args.extend_from_slice(&client);
    let map = RoamProcess::start(&map_args, root, "service ready");
    let mut node_args = vec!["ros2", "--config", &ros2];
    node_args.extend_from_slice(&client);
    let node = RoamProcess::start(&node_args, root, "driving a Nav2 robot");
    vec![router, map, node]
}

/// `roam mission` drives the fake Nav2 robot through the built-in day (the demo's
/// tasks, `roam_mission::tasks::day`): every window on time, and the time model the
/// executive fits from what the robot drove (the missions that arrived and the parts
/// of replaced ones, more drives than windows) is within [`V_LIN_TOLERANCE`] of the
/// robot's speed, where Table I's prior (2 s/m) is 20% off.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn roam_mission_drives_a_nav2_robot_through_the_day() {
    if !has_python("roam_mission_drives_a_nav2_robot_through_the_day") {
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    let port = free_loopback_port().expect("port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let root = format!("nav2-day-{}", std::process::id());
    let mut processes = site(dir.path(), &endpoint, &root);
    let client = ["--mode", "client", "--connect", endpoint.as_str()];
    let mut planner_args = vec!["planner"];
    planner_args.extend_from_slice(&client);
    processes.push(RoamProcess::start(&planner_args, &root, "service ready"));

    let calibration = dir.path().join("nav.calibration.json");
    let tasks: String = roam_mission::tasks::day()
        .iter()
        .map(|t| {
            format!(
                "    - {{ name: {}, at: [{}, {}], start_s: {}, duration_s: {} }}\n",
                t.name, t.at[0], t.at[1], t.start_s, t.duration_s
            )
        })
        .collect();
    let mission = write(
        dir.path(),
        "mission.yaml",
        &format!(
            "executive:\n  robot: nav\n  tasks:\n{tasks}  model: model1\n  plan_deadline_s: 1.0\n  max_generations: 1000\n  slack_s: 10.0\n  slack_interval_s: 10.0\n  calibrate: true\n  calibration_file: {}\n",
            calibration.display()
        ),
    );
    let session = roam_runtime::session::open(
        SessionArgs::client_of(&endpoint)
            .zenoh_config(None)
            .expect("config"),
    )
    .await
    .expect("session");
    let reports = session
        .declare_subscriber(keys::robot_mission_report(&root, "nav"))
        .await
        .expect("report subscriber");
    let mut mission_args = vec!["mission", "--config", &mission];
    mission_args.extend_from_slice(&client);
    processes.push(RoamProcess::start(&mission_args, &root, "service ready"));

    let connect = endpoint.clone();
    let robot = tokio::task::spawn_blocking(move || fake_robot(&connect, "360", &[]))
        .await
        .expect("python");
    assert!(
        robot.status.success(),
        "the fake Nav2 robot failed: {robot:?}"
    );
    let driven: serde_json::Value = serde_json::from_str(&robot.stdout).expect("json");
    eprintln!("the fake Nav2 robot: {driven}");

    let mut windows: Vec<WindowReport> = Vec::new();
    while let Ok(Some(sample)) = reports.try_recv() {
        windows.push(roam_proto::decode(&sample.payload().to_bytes()).expect("report"));
    }
    let day = roam_mission::tasks::day();
    assert_eq!(windows.len(), day.len(), "a report per window: {windows:?}");
    for w in &windows {
        eprintln!(
            "window {} ({}): arrived {:?} for {} s, {} replans",
            w.window, w.task, w.arrival_s, w.task_start_s, w.replans
        );
        assert!(w.on_time, "window {} is late: {w:?}", w.window);
    }
    assert!(
        driven["succeeded"].as_u64() >= Some(day.len() as u64),
        "{driven}"
    );

    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&calibration).expect("calibration"))
            .expect("json");
    let v_lin = fit["model"]["v_lin"].as_f64().expect("v_lin");
    let truth = 1.0 / SPEED_M_PER_S;
    eprintln!(
        "time model: v_lin {v_lin:.3} s/m against the robot's {truth:.3} ({:+.1}%)",
        100.0 * (v_lin / truth - 1.0)
    );
    assert!(
        (v_lin / truth - 1.0).abs() <= V_LIN_TOLERANCE,
        "the time model is not within {V_LIN_TOLERANCE} of the robot's speed: {fit}"
    );
    let drives = fit["statistics"]["stretches"].as_u64().expect("stretches");
    assert!(
        drives > day.len() as u64,
        "replaced missions teach too, not only the {} arrivals: {fit}",
        day.len()
    );
    let _ = session.close().await;
}

/// The bridge alone, through Zenoh: a mission for `nav` becomes a FollowPath goal that
/// completes, the poses become estimates with their covariance as the CRB; a server that
/// rejects every goal or never answers leaves the robot `stuck`, and a pose stream that
/// stops leaves it `halted_stale`: each reported on the controller's key, none hangs.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_nav2_bridge_reports_rejections_silence_and_lost_poses() {
    if !has_python("the_nav2_bridge_reports_rejections_silence_and_lost_poses") {
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    let port = free_loopback_port().expect("port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let root = format!("nav2-bridge-{}", std::process::id());
    let _processes = site(dir.path(), &endpoint, &root);
    let session = roam_runtime::session::open(
        SessionArgs::client_of(&endpoint)
            .zenoh_config(None)
            .expect("config"),
    )
    .await
    .expect("session");
    // Everything the bridge says, kept as it comes: a subscriber that stops reading
    // would hold the router's queue to it.
    let heard_statuses: Arc<Mutex<Vec<ControllerStatus>>> = Arc::default();
    let heard_estimates: Arc<Mutex<Vec<PositionEstimate>>> = Arc::default();
    let _statuses = session
        .declare_subscriber(keys::robot_controller(&root, "nav"))
        .callback(keep(heard_statuses.clone()))
        .await
        .expect("status subscriber");
    let _estimates = session
        .declare_subscriber(keys::robot_estimate(&root, "nav"))
        .callback(keep(heard_estimates.clone()))
        .await
        .expect("estimate subscriber");
    let wait_for = |what: String, found: &dyn Fn() -> bool| {
        let started = std::time::Instant::now();
        while !found() {
            assert!(
                started.elapsed() < Duration::from_secs(30),
                "{what}: not within 30 s"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    };

    let mut states = Vec::new();
    // 2 m, and 48 m (80 s of simulated driving: the poses stop on the way).
    let short = vec![[-8.0, -6.0], [-6.0, -6.0]];
    let long = vec![[-8.0, 8.0], [8.0, 8.0], [8.0, -8.0]];
    for (case, extra, waypoints, want) in [
        ("drives", &[][..], &short, MissionState::Completed),
        ("rejects", &["--reject"][..], &short, MissionState::Stuck),
        (
            "never answers",
            &["--silent"][..],
            &short,
            MissionState::Stuck,
        ),
        (
            "loses its pose",
            &["--stop-pose-at", "20"][..],
            &long,
            MissionState::HaltedStale,
        ),
    ] {
        heard_statuses.lock().expect("lock").clear();
        heard_estimates.lock().expect("lock").clear();
        let connect = endpoint.clone();
        let args: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        let robot = std::thread::spawn(move || {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            fake_robot(&connect, "60", &args)
        });
        // An estimate from this run's robot (its clock starts at 0; the last run's ended
        // at 60 s) says it is there, with its covariance as the CRB; then the mission.
        let fresh = || {
            heard_estimates
                .lock()
                .expect("lock")
                .iter()
                .find(|e| e.time_s < 10.0)
                .cloned()
        };
        wait_for(format!("{case}: an estimate"), &|| fresh().is_some());
        let crb = fresh()
            .and_then(|e| e.crb)
            .expect("the covariance as the CRB");
        assert!((crb[0][0] - 0.01).abs() < 1e-9 && (crb[1][1] - 0.01).abs() < 1e-9);
        let mission = Mission {
            after_step: None,
            robot: "nav".into(),
            id: format!("case-{}", states.len()),
            waypoints: waypoints.clone(),
            recovery: false,
        };
        session
            .put(
                keys::robot_mission(&root, "nav"),
                roam_proto::encode(&mission),
            )
            .await
            .expect("mission");
        wait_for(format!("{case}: {want:?}"), &|| {
            heard_statuses
                .lock()
                .expect("lock")
                .iter()
                .any(|s| s.mission.as_deref() == Some(mission.id.as_str()) && s.state == want)
        });
        eprintln!("{case}: {want:?}");
        states.push(want);
        let run = robot.join().expect("python");
        assert!(run.status.success(), "{case}: {run:?}");
    }
    let _ = session.close().await;
}
