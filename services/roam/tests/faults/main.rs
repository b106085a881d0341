//! Kill -9 every service in turn during a mission. Each role runs as its own `roam`
//! process behind one router, as on a fleet; this test is their supervisor (what
//! systemd's `Restart=always` or compose's `restart: always` is in production): it
//! SIGKILLs one process, starts it again, and waits for its liveliness token. It talks
//! to the stack only through Zenoh, as a client would.
//!
//! What must hold: the robot still reaches both of the day's tasks (a window report
//! with an arrival for each), and no map layer's version ever goes back (the map
//! server restores its layers from its data dir; the sim resumes from its snapshot).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_proto::mission::WindowReport;
use roam_proto::{decode, keys};
use roam_runtime::{Requester, SessionArgs};
use roam_stack::router::free_loopback_port;

mod fleet;
mod watch;

use fleet::Fleet;
use watch::{none_lost, versions, wait_live, Watch};

/// The sim's real-time factor: the day's 170 s take about 35 s of wall time, long
/// enough for seven kills and restarts while the robot drives.
const SIM_RATE: &str = "5";

fn repo(path: &str) -> String {
    format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write config");
    path
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_service_killed_in_turn_comes_back_and_the_mission_completes() {
    let port = free_loopback_port().expect("port");
    let mut fleet = Fleet::new(
        format!("faults-{}", std::process::id()),
        format!("tcp/127.0.0.1:{port}"),
    );
    let router_args: Vec<String> = ["router", "--listen", &fleet.endpoint, "--no-multicast"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    fleet.procs.add(None, "router", router_args);
    fleet.start("router");

    let dir = fleet.dir.path().to_owned();
    let data = dir.join("map-data");
    let sim_state = dir.join("sim.json");
    // The slack rule off: a slack replan right after the controller's restart would
    // resend the mission before the silence rule this test watches for has to.
    let mission = std::fs::read_to_string(repo("config/mission.yaml"))
        .expect("config/mission.yaml")
        .replace("root: roam", &format!("root: {}", fleet.root))
        .replace("slack_s: 10.0", "slack_s: .inf");
    assert!(
        mission.contains("slack_s: .inf"),
        "config/mission.yaml sets slack_s"
    );
    let mission = write(&dir, "mission.yaml", &mission);
    let (data, sim_state, mission) = (
        data.display().to_string(),
        sim_state.display().to_string(),
        mission.display().to_string(),
    );
    let controller = repo("config/controller.yaml");
    fleet.add("map-server", "m", &["--data-dir", &data]);
    fleet.add("planner", "a", &[]);
    fleet.add("planner", "b", &[]);
    fleet.add(
        "sim",
        "w",
        &["--rate", SIM_RATE, "--state-file", &sim_state],
    );
    fleet.add("localization", "l", &[]);
    // The controller's config names the default root; `--root` wins over the file.
    fleet.add("controller", "c", &["--config", &controller]);
    fleet.add("mapper", "p", &[]);
    fleet.add("mission", "x", &["--config", &mission]);
    let names: Vec<String> = fleet.roles.iter().map(|r| r.name.clone()).collect();
    for name in &names {
        fleet.start(name);
    }

    let session = {
        let started = Instant::now();
        loop {
            let config = SessionArgs::client_of(&fleet.endpoint)
                .zenoh_config(None)
                .expect("config");
            match roam_runtime::session::open(config).await {
                Ok(s) => break s,
                Err(e) if started.elapsed() > Duration::from_secs(20) => {
                    panic!("no router: {e}\n{}", fleet.logs())
                }
                Err(_) => tokio::time::sleep(Duration::from_millis(100)).await,
            }
        }
    };
    for i in 0..fleet.roles.len() {
        let key = fleet.roles[i].live_key.clone();
        fleet.restart_exited();
        assert!(
            wait_live(&session, &key, true, Duration::from_secs(30)).await,
            "{key} never came up\n{}",
            fleet.logs()
        );
    }
    let reports: Arc<Mutex<Vec<WindowReport>>> = Arc::default();
    let _reports = {
        let reports = reports.clone();
        session
            .declare_subscriber(keys::robot_mission_report(&fleet.root, "robot"))
            .callback(move |s| {
                if let Ok(r) = decode::<WindowReport>(&s.payload().to_bytes()) {
                    reports.lock().expect("reports").push(r);
                }
            })
            .await
            .expect("subscribe to the window reports")
    };
    let requester = Requester::new(session.clone(), Duration::from_secs(5));

    // Kill each role in turn, two seconds apart, while the robot drives to goal1.
    let mut watch = Watch {
        session: &session,
        requester: &requester,
        started: Instant::now(),
        seen: BTreeMap::new(),
        downtime: Vec::new(),
    };
    for name in [
        "planner-a",
        "localization-l",
        "controller-c",
        "map-server-m",
        "sim-w",
        "mapper-p",
        "planner-b",
    ] {
        tokio::time::sleep(Duration::from_secs(2)).await;
        watch.kill_and_restart(&mut fleet, name).await;
    }
    // The executive dies after goal1 is over: its successor skips goal1, drives to
    // goal2 and reports it.
    let goal1 = watch.report(&mut fleet, &reports, "goal1").await;
    watch.kill_and_restart(&mut fleet, "mission-x").await;
    let goal2 = watch.report(&mut fleet, &reports, "goal2").await;
    for r in [&goal1, &goal2] {
        assert!(
            r.arrival_s.is_some(),
            "the robot never reached {}: {r:?}\n{}",
            r.task,
            fleet.logs()
        );
    }
    let (started, seen, downtime) = (watch.started, watch.seen, watch.downtime);
    let last = versions(&requester, &fleet.root)
        .await
        .expect("versions at the end");
    none_lost(&seen, &last).unwrap_or_else(|e| panic!("at the end: {e}"));
    // Each restart recovered its state the intended way, not by luck.
    for (log, line, what) in [
        (
            "sim-w",
            "resumed from the snapshot",
            "the restarted sim resumed from its snapshot",
        ),
        (
            "map-server-m",
            "restored the layers",
            "the restarted map server restored its layers",
        ),
        (
            "mission-x",
            "skipped",
            "the restarted executive skipped the task that was over",
        ),
    ] {
        let text = std::fs::read_to_string(dir.join(format!("{log}.log"))).unwrap_or_default();
        assert!(text.contains(line), "not seen: {what}\n{}", fleet.logs());
    }
    // The restarted controller starts with no mission: the executive must send it one.
    // Which rule does so first is timing (the silence rule, or a last-safe-moment
    // replan that falls inside the silence timeout); either is the executive's job done.
    let controller = std::fs::read_to_string(dir.join("controller-c.log")).unwrap_or_default();
    let after_restart = controller
        .rfind("service ready")
        .map(|at| &controller[at..])
        .unwrap_or_default();
    assert!(
        after_restart.contains("mission set"),
        "not seen: the executive resent the mission the restarted controller lost\n{}",
        fleet.logs()
    );
    for (name, took) in &downtime {
        println!(
            "{name}: killed and live again in {:.2} s",
            took.as_secs_f64()
        );
    }
    for r in reports.lock().expect("reports").iter() {
        println!(
            "{}: arrived {:?} s, task at {} s, replans {} ({:?})",
            r.task, r.arrival_s, r.task_start_s, r.replans, r.replan_reasons
        );
    }
    println!("the whole run: {:.1} s", started.elapsed().as_secs_f64());
}
