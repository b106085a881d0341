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
use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam::router::free_loopback_port;
use roam_proto::map::LayerList;
use roam_proto::mission::WindowReport;
use roam_proto::{decode, keys};
use roam_runtime::{Requester, SessionArgs};

const ROAM: &str = env!("CARGO_BIN_EXE_roam");
/// The sim's real-time factor: the day's 170 s take about 35 s of wall time, long
/// enough for seven kills and restarts while the robot drives.
const SIM_RATE: &str = "5";
/// The whole run, kills and the mission, must end within this.
const RUN_LIMIT: Duration = Duration::from_secs(240);

fn repo(path: &str) -> String {
    format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))
}

/// One supervised role: how to start it, and its process now.
struct Role {
    /// The service name in its liveliness key (`<root>/@live/<service>/<instance>`).
    service: &'static str,
    instance: &'static str,
    args: Vec<String>,
    child: Option<Child>,
    restarts: u32,
}

/// The processes of one stack, their logs in one directory.
struct Fleet {
    dir: tempfile::TempDir,
    root: String,
    endpoint: String,
    router: Option<Child>,
    roles: Vec<Role>,
}

impl Fleet {
    fn log(&self, name: &str) -> File {
        OpenOptions::new()
            .create(true)
            .append(true)
            .open(self.dir.path().join(format!("{name}.log")))
            .expect("log file")
    }

    fn spawn(&self, name: &str, args: &[String]) -> Child {
        Command::new(ROAM)
            .args(args)
            .env("RUST_LOG", "info")
            .stdout(Stdio::null())
            .stderr(self.log(name))
            .spawn()
            .expect("spawn roam")
    }

    fn start(&mut self, i: usize) {
        let name = format!("{}-{}", self.roles[i].service, self.roles[i].instance);
        let child = self.spawn(&name, &self.roles[i].args.clone());
        self.roles[i].child = Some(child);
    }

    /// SIGKILL (Rust's `Child::kill` on Unix), then reap it.
    fn kill(&mut self, i: usize) {
        if let Some(mut child) = self.roles[i].child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }

    fn live_key(&self, i: usize) -> String {
        format!(
            "{}/@live/{}/{}",
            self.root, self.roles[i].service, self.roles[i].instance
        )
    }

    /// Every role that died on its own since the last look is started again, as a
    /// supervisor would (a mission executive that failed, say).
    fn restart_exited(&mut self) {
        for i in 0..self.roles.len() {
            let exited = self.roles[i]
                .child
                .as_mut()
                .is_some_and(|c| matches!(c.try_wait(), Ok(Some(_))));
            if exited {
                self.roles[i].restarts += 1;
                self.start(i);
            }
        }
    }

    fn logs(&self) -> String {
        let mut all = String::new();
        let mut names: Vec<_> = std::fs::read_dir(self.dir.path())
            .map(|d| d.flatten().map(|e| e.path()).collect())
            .unwrap_or_default();
        names.sort();
        for path in names
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "log"))
        {
            let text = std::fs::read_to_string(path).unwrap_or_default();
            let tail: Vec<&str> = text.lines().rev().take(25).collect();
            all.push_str(&format!("== {}\n", path.display()));
            for line in tail.iter().rev() {
                all.push_str(line);
                all.push('\n');
            }
        }
        all
    }
}

impl Drop for Fleet {
    fn drop(&mut self) {
        for i in 0..self.roles.len() {
            self.kill(i);
        }
        if let Some(mut r) = self.router.take() {
            let _ = r.kill();
            let _ = r.wait();
        }
    }
}

fn client_args(endpoint: &str, root: &str, instance: &str) -> Vec<String> {
    [
        "--mode",
        "client",
        "--connect",
        endpoint,
        "--no-multicast",
        "--root",
        root,
        "--instance",
        instance,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

fn role(service: &'static str, instance: &'static str, extra: &[&str], fleet: &Fleet) -> Role {
    let mut args = vec![service.to_owned()];
    args.extend(client_args(&fleet.endpoint, &fleet.root, instance));
    args.extend(extra.iter().map(|s| s.to_string()));
    Role {
        service,
        instance,
        args,
        child: None,
        restarts: 0,
    }
}

async fn is_live(session: &zenoh::Session, key: &str) -> bool {
    match session
        .liveliness()
        .get(key)
        .timeout(Duration::from_millis(500))
        .await
    {
        Ok(replies) => replies.recv_async().await.is_ok(),
        Err(_) => false,
    }
}

async fn wait_live(session: &zenoh::Session, key: &str, live: bool, limit: Duration) -> bool {
    let started = Instant::now();
    while started.elapsed() < limit {
        if is_live(session, key).await == live {
            return true;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    false
}

async fn versions(requester: &Requester, root: &str) -> Option<BTreeMap<String, u64>> {
    let list: LayerList = requester
        .request::<LayerList, LayerList>(&keys::map_index(root), None)
        .await
        .ok()?;
    Some(
        list.layers
            .into_iter()
            .map(|l| (l.name, l.version))
            .collect(),
    )
}

/// Every layer seen before is there with at least its version.
fn none_lost(before: &BTreeMap<String, u64>, after: &BTreeMap<String, u64>) -> Result<(), String> {
    for (name, v) in before {
        match after.get(name) {
            Some(w) if w >= v => {}
            Some(w) => return Err(format!("layer {name} went back from version {v} to {w}")),
            None => return Err(format!("layer {name} (version {v}) is gone")),
        }
    }
    Ok(())
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write config");
    path
}

/// What the test watches while it kills: the map's versions and each role's downtime.
struct Watch<'a> {
    session: &'a zenoh::Session,
    requester: &'a Requester,
    started: Instant,
    seen: BTreeMap<String, u64>,
    downtime: Vec<(String, Duration)>,
}

impl Watch<'_> {
    /// The latest versions, checked against every version seen before.
    async fn check_versions(&mut self, fleet: &Fleet, when: &str) {
        let now = loop {
            if let Some(v) = versions(self.requester, &fleet.root).await {
                break v;
            }
            assert!(
                self.started.elapsed() < RUN_LIMIT,
                "the map server stopped answering {when}\n{}",
                fleet.logs()
            );
        };
        none_lost(&self.seen, &now).unwrap_or_else(|e| panic!("{when}: {e}\n{}", fleet.logs()));
        self.seen = now;
    }

    /// SIGKILL one role, start it again, wait for its liveliness token.
    async fn kill_and_restart(&mut self, fleet: &mut Fleet, name: &str) {
        fleet.restart_exited();
        self.check_versions(fleet, &format!("before killing {name}"))
            .await;
        let i = fleet
            .roles
            .iter()
            .position(|r| format!("{}-{}", r.service, r.instance) == name)
            .expect("a role of the fleet");
        let key = fleet.live_key(i);
        let killed = Instant::now();
        fleet.kill(i);
        assert!(
            wait_live(self.session, &key, false, Duration::from_secs(10)).await,
            "{key} stayed live after SIGKILL"
        );
        fleet.roles[i].restarts += 1;
        fleet.start(i);
        assert!(
            wait_live(self.session, &key, true, Duration::from_secs(30)).await,
            "{key} did not come back\n{}",
            fleet.logs()
        );
        self.downtime.push((name.to_owned(), killed.elapsed()));
        self.check_versions(fleet, &format!("after killing {name}"))
            .await;
    }

    /// Waits for the window report of `task`, restarting what exits meanwhile.
    async fn report(
        &mut self,
        fleet: &mut Fleet,
        reports: &Mutex<Vec<WindowReport>>,
        task: &str,
    ) -> WindowReport {
        loop {
            fleet.restart_exited();
            let done: Vec<WindowReport> = reports.lock().expect("reports").clone();
            if let Some(r) = done.iter().find(|r| r.task == task) {
                return r.clone();
            }
            assert!(
                self.started.elapsed() < RUN_LIMIT,
                "no report for {task} within {RUN_LIMIT:?}; reports: {done:?}\n{}",
                fleet.logs()
            );
            tokio::time::sleep(Duration::from_millis(200)).await;
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_service_killed_in_turn_comes_back_and_the_mission_completes() {
    let port = free_loopback_port().expect("port");
    let mut fleet = Fleet {
        dir: tempfile::tempdir().expect("temp dir"),
        root: format!("faults-{}", std::process::id()),
        endpoint: format!("tcp/127.0.0.1:{port}"),
        router: None,
        roles: Vec::new(),
    };
    let router_args: Vec<String> = ["router", "--listen", &fleet.endpoint, "--no-multicast"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    fleet.router = Some(fleet.spawn("router", &router_args));

    let dir = fleet.dir.path().to_owned();
    let data = dir.join("map-data");
    let sim_state = dir.join("sim.json");
    let mission = std::fs::read_to_string(repo("config/mission.yaml"))
        .expect("config/mission.yaml")
        .replace("root: roam", &format!("root: {}", fleet.root));
    let mission = write(&dir, "mission.yaml", &mission);
    let roles = vec![
        role(
            "map-server",
            "m",
            &["--data-dir", &data.display().to_string()],
            &fleet,
        ),
        role("planner", "a", &[], &fleet),
        role("planner", "b", &[], &fleet),
        role(
            "sim",
            "w",
            &[
                "--rate",
                SIM_RATE,
                "--state-file",
                &sim_state.display().to_string(),
            ],
            &fleet,
        ),
        role("localization", "l", &[], &fleet),
        role(
            "controller",
            "c",
            &["--config", &repo("config/controller.yaml")],
            &fleet,
        ),
        role("mapper", "p", &[], &fleet),
        role(
            "mission",
            "x",
            &["--config", &mission.display().to_string()],
            &fleet,
        ),
    ];
    fleet.roles = roles;
    // The controller's config names the default root; `--root` wins over the file.
    for i in 0..fleet.roles.len() {
        fleet.start(i);
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
        let key = fleet.live_key(i);
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
            "went silent",
            "the executive resent the mission the restarted controller lost",
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
