//! `roam bench fleet`: many robots in closed loop through Zenoh (issues 16 and 30).
//!
//! The sim, localization and the APF controller run in this process on the built-in
//! world, as in `roam stack`; the router runs in a process of its own (`<program> router`,
//! the `roam` binary, on a free loopback port), so that its CPU and memory are measured
//! apart from the loop's. A client adds `robots − 1` robots on free cells spread over the
//! map and gives each a mission across the map and back (waypoints, paper 002's
//! controller), then resumes the sim at `rate_hz` steps per second for `seconds`. Every
//! step the loop is sim → `ranges` → localization → `estimate` → controller → `cmd` →
//! sim, for every robot, over Zenoh.
//!
//! **On time.** A command answers the estimate of step k (it carries k); it is on time
//! when it reaches the bench's subscriber before the sim's clock for step k + 1 does
//! (the sim applies a command at the next step, so a later one misses its step). Both
//! arrive through the same router as at the sim, so the order seen here is the order
//! the sim sees, to within the router's fan-out. `loop_on_time_share` is the commands
//! on time over the robots × steps that should have had one (each robot's steps from its
//! first command on); `sim_on_time_share` is the sim's own count of steps whose messages
//! were out before the next step was due.
//!
//! `cpu_share` is this process's CPU time (the loop without the router) over wall time
//! and cores (1.0: every core busy); `rss_per_robot_mib` the resident memory the robots
//! added (after minus before adding them, over the robots). `router_*` are the same for
//! the router's process, read from `/proc/<pid>`.
//!
//! **Join.** Halfway through the timed run the last of the `robots` joins: its mission
//! is put, then the sim adds it while it runs, as an operator's tool would. The joiner
//! is one of `robots` (not one more), so `robots` may be the sim's whole `max_robots`.
//! `join_ms` is from its first range scan to its first command, both as the bench's
//! subscriber sees them (the path localization's and the sim's subscriptions take).
//!
//! **Router restart.** After the timed run the sim runs on at the same rate; after
//! [`RESTART_LEAD`] the router's process is killed with SIGKILL (a crash: the kernel
//! closes its sockets, so every client sees its link go at once) and a new one is
//! started on the same endpoint [`ROUTER_DOWN`] later. Nothing else is restarted: every
//! session is a Zenoh client of that endpoint and reconnects by itself. The bench waits
//! (at most [`RECOVERY_LIMIT`]) until every robot's command reaches its subscriber
//! again, runs [`RESTART_TAIL`] more and pauses the sim. The outage's steps are those
//! from the last clock seen before the kill to the last seen when every robot had been
//! commanded again; the commands on time are counted inside it and outside it (the
//! steps of this phase before and after it) apart.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use roam_controller::service::ControllerConfig;
use roam_localization::service::LocalizationConfig;
use roam_proto::controller::Mission;
use roam_proto::sim::{RobotCommand, SimClock, SimControl, SimStatus};
use roam_proto::{decode, encode, keys};
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::{Requester, SessionArgs};
use roam_sim::service::SimConfig;
use roam_world::grid::cell_center;
use roam_world::scenario::load_or_builtin;
use serde::Serialize;

use crate::{ms, setup, BenchError};
use tokio_util::sync::CancellationToken;

use crate::process::{cpu_seconds_of, peak_rss_mib, peak_rss_mib_of, rss_mib, rss_mib_of};
use crate::sim::{run_sim_for, TimedRun};
use roam_experiments::progress::{Done, Progress};
use roam_stack::router::free_loopback_port;
use roam_stack::stack::wait_until_live;

/// How long the restart phase runs steadily before the router is killed.
pub const RESTART_LEAD: Duration = Duration::from_secs(2);
/// How long the router stays down: from its SIGKILL to the start of the new one (what
/// `deploy/systemd/roam@.service` waits before it restarts a role, `RestartSec=1s`).
pub const ROUTER_DOWN: Duration = Duration::from_secs(1);
/// How long after the restart the bench waits for every robot to be commanded again
/// before it reports how many were.
pub const RECOVERY_LIMIT: Duration = Duration::from_secs(30);
/// How long the restart phase runs on after every robot has been commanded again.
pub const RESTART_TAIL: Duration = Duration::from_secs(2);
/// How long a new router process may take to accept its first client.
const ROUTER_START_LIMIT: Duration = Duration::from_secs(20);

#[derive(Debug, Clone, Serialize)]
pub struct FleetBench {
    /// Robots at the end of the timed run: `robots − 1` from its start and the one that
    /// joined halfway.
    pub robots: usize,
    pub rate_hz: f64,
    pub seconds: f64,
    /// Sim steps while running.
    pub steps: u64,
    pub sim_on_time_share: f64,
    /// Commands that answered step k and arrived before step k + 1's clock, over the
    /// commands the steps called for.
    pub loop_on_time_share: f64,
    pub commands_expected: u64,
    pub commands_on_time: u64,
    pub commands_late: u64,
    /// Step k + 1's clock minus step k's, at the subscriber: median and 99th percentile.
    pub step_period_p50_ms: f64,
    pub step_period_p99_ms: f64,
    /// The loop's process (sim, localization, controller, the bench's client; not the
    /// router): CPU time over wall time and cores during the timed run.
    pub cpu_share: f64,
    pub cores: usize,
    pub rss_per_robot_mib: f64,
    pub rss_mib: Option<f64>,
    pub peak_rss_mib: Option<f64>,
    /// The router's process: CPU time over wall time and cores during the timed run.
    pub router_cpu_share: f64,
    /// The router's CPU time per robot and step during the timed run, microseconds
    /// (its share of one core per robot is this × `rate_hz` / 10⁶).
    pub router_cpu_us_per_robot_step: f64,
    /// The router's resident memory at the end of the timed run (`VmRSS`), MiB.
    pub router_rss_mib: Option<f64>,
    /// The router's peak resident memory up to then (`VmHWM`), MiB.
    pub router_peak_rss_mib: Option<f64>,
    /// What the robots added to the router's resident memory, over the robots, MiB.
    pub router_rss_per_robot_mib: f64,
    /// The joining robot: from its first range scan to its first command, both at the
    /// bench's subscriber, ms (`None`: never commanded).
    pub join_ms: Option<f64>,
    /// The joining robot: from the request that added it to its first command, ms.
    pub join_from_add_ms: Option<f64>,
    /// From the router's SIGKILL to the start of the new router, ms ([`ROUTER_DOWN`]
    /// and the time to start a process).
    pub restart_down_ms: f64,
    /// From the new router's start to the first command of any robot after it, ms.
    pub restart_first_command_ms: Option<f64>,
    /// From the new router's start until every robot had been commanded again, ms
    /// (`None`: not every robot within [`RECOVERY_LIMIT`]).
    pub restart_all_commanded_ms: Option<f64>,
    /// The robots commanded again after the restart (of `robots`).
    pub restart_robots_commanded: usize,
    /// The restart phase's steps outside the outage (before the kill, after every
    /// robot was commanded again), and the commands on time in them over robots × steps.
    pub restart_steps_outside: u64,
    pub restart_on_time_share_outside: f64,
    /// The outage's steps (last clock before the kill to the clock when every robot
    /// had been commanded again), and the commands on time in them over robots × steps.
    pub restart_steps_inside: u64,
    pub restart_on_time_share_inside: f64,
}

/// What the subscribers saw.
#[derive(Debug, Default)]
struct Seen {
    /// The latest clock step, and when each clock arrived.
    clocks: Vec<(u64, Instant)>,
    /// Per robot, the first step it had a command for and when that command arrived.
    first: HashMap<String, (u64, Instant)>,
    on_time: u64,
    late: u64,
    /// Per step, the commands for it that were on time.
    on_time_at: BTreeMap<u64, u64>,
    /// From this instant on (the router's restart), per robot, when its first command
    /// arrived.
    since: Option<Instant>,
    again: HashMap<String, Instant>,
}

/// Runs the bench with the router in its own process, `router_program router` (the
/// `roam` binary); `progress` each second of the timed run (stage `running`), then per
/// robot commanded again after the router's restart (stage `router restart`).
pub async fn fleet(
    robots: usize,
    rate_hz: f64,
    seconds: f64,
    router_program: &Path,
    progress: Progress<'_>,
) -> Result<FleetBench, BenchError> {
    let most = roam_sim::sim::MAX_ROBOTS;
    if robots == 0 || robots > most {
        return Err(BenchError::Setup(format!(
            "a fleet is 1..={most} robots (the sim's robot limit), not {robots}"
        )));
    }
    let (mut router, session) = start_router(router_program).await?;
    let root = "roam-bench-fleet".to_owned();
    let cancel = CancellationToken::new();
    let client_config = || {
        SessionArgs::client_of(&router.endpoint)
            .zenoh_config(None)
            .map_err(setup)
    };
    let mut services = tokio::task::JoinSet::new();
    {
        let (config, zenoh, token) = (
            SimConfig {
                service: ServiceConfig::at(root.clone()),
                rate: None,
                ..SimConfig::default()
            },
            client_config()?,
            cancel.clone(),
        );
        services.spawn(async move {
            roam_sim::service::run(config, zenoh, token)
                .await
                .map_err(|e| e.to_string())
        });
    }
    {
        let (config, zenoh, token) = (
            LocalizationConfig {
                service: ServiceConfig::at(root.clone()),
                publish_peb_layer: false,
                ..LocalizationConfig::default()
            },
            client_config()?,
            cancel.clone(),
        );
        services.spawn(async move {
            roam_localization::service::run(config, zenoh, token)
                .await
                .map_err(|e| e.to_string())
        });
    }
    {
        let (config, zenoh, token) = (
            ControllerConfig {
                service: ServiceConfig::at(root.clone()),
                ..ControllerConfig::default()
            },
            client_config()?,
            cancel.clone(),
        );
        services.spawn(async move {
            roam_controller::service::run(config, zenoh, token)
                .await
                .map_err(|e| e.to_string())
        });
    }
    let result = run(
        &mut router,
        router_program,
        &root,
        &session,
        robots,
        (rate_hz, seconds),
        progress,
    )
    .await;
    cancel.cancel();
    let _ = tokio::time::timeout(Duration::from_secs(10), async {
        while services.join_next().await.is_some() {}
    })
    .await;
    let _ = session.close().await;
    router.kill();
    result
}

/// The router in its own process, `<program> router --listen <endpoint>
/// --no-multicast`, its output dropped; killed with SIGKILL when dropped.
struct RouterProcess {
    child: Child,
    endpoint: String,
}

impl RouterProcess {
    fn spawn(program: &Path, endpoint: &str) -> Result<RouterProcess, BenchError> {
        let child = Command::new(program)
            .args(["router", "--listen", endpoint, "--no-multicast"])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| {
                BenchError::Setup(format!(
                    "cannot start the router ({} router): {e}",
                    program.display()
                ))
            })?;
        Ok(RouterProcess {
            child,
            endpoint: endpoint.to_owned(),
        })
    }

    fn pid(&self) -> u32 {
        self.child.id()
    }

    /// How the process ended, if it has.
    fn exited(&mut self) -> Option<ExitStatus> {
        self.child.try_wait().ok().flatten()
    }

    /// SIGKILL, and reaps the process.
    fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for RouterProcess {
    fn drop(&mut self) {
        self.kill();
    }
}

/// A router process on a free loopback port, and a client session of it (the bench's).
/// A router that exits before it accepts a client (another process took the port in
/// between) is tried again on another port, five times in all.
async fn start_router(program: &Path) -> Result<(RouterProcess, zenoh::Session), BenchError> {
    let mut last = String::from("no attempt");
    for _ in 0..5 {
        let port = free_loopback_port().map_err(setup)?;
        let mut router = RouterProcess::spawn(program, &format!("tcp/127.0.0.1:{port}"))?;
        let started = Instant::now();
        loop {
            // A session only once the port takes connections: Zenoh warns of each one
            // refused.
            if std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
                last = format!("nothing listens on {} yet", router.endpoint);
            } else {
                let config = SessionArgs::client_of(&router.endpoint)
                    .zenoh_config(None)
                    .map_err(setup)?;
                match roam_runtime::session::open(config).await {
                    Ok(session) => return Ok((router, session)),
                    Err(e) => last = e.to_string(),
                }
            }
            if let Some(status) = router.exited() {
                last = format!("the router on {} exited ({status})", router.endpoint);
                break;
            }
            if started.elapsed() > ROUTER_START_LIMIT {
                return Err(BenchError::Setup(format!(
                    "the router on {} accepted no client within {ROUTER_START_LIMIT:?}: {last}",
                    router.endpoint
                )));
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }
    Err(BenchError::Setup(format!(
        "no router could be started ({} router): {last}",
        program.display()
    )))
}

/// What the robots are: where each starts and its mission, the last one the joiner.
struct Fleet {
    places: Vec<[f64; 2]>,
}

impl Fleet {
    fn name(k: usize) -> String {
        format!("fleet-{k}")
    }

    /// Robot `k`'s mission: to the robot half the fleet away and back.
    fn mission(&self, k: usize) -> Mission {
        let n = self.places.len();
        Mission {
            after_step: None,
            robot: Fleet::name(k),
            id: format!("bench-{k}"),
            waypoints: vec![self.places[(k + n / 2) % n], self.places[k]],
            recovery: false,
        }
    }
}

/// `robots` places on free cells (every 8-neighbour free too) spread over the built-in
/// world, and its own robots' names (they leave the sim first).
fn places(robots: usize) -> Result<(Fleet, Vec<String>), BenchError> {
    let (_, scenario) = load_or_builtin(None).map_err(setup)?;
    let meta = scenario.occupancy.meta;
    let width = meta.width as usize;
    let free: Vec<usize> = scenario
        .occupancy
        .cells
        .iter()
        .enumerate()
        .filter(|(i, &c)| {
            let (x, y) = (i % width, i / width);
            // Away from walls: every 8-neighbour free too.
            c == 0
                && (-1i64..=1).all(|dy| {
                    (-1i64..=1).all(|dx| {
                        let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                        nx >= 0
                            && ny >= 0
                            && (nx as usize) < width
                            && (ny as usize) < meta.height as usize
                            && scenario.occupancy.cells[ny as usize * width + nx as usize] == 0
                    })
                })
        })
        .map(|(i, _)| i)
        .collect();
    if free.len() < robots {
        return Err(BenchError::Setup(format!(
            "the built-in world has only {} free cells",
            free.len()
        )));
    }
    let stride = free.len() / robots;
    let places = (0..robots)
        .map(|k| {
            let i = free[k * stride];
            let (x, y) = cell_center(&meta, i % width, i / width);
            [x, y]
        })
        .collect();
    let own = scenario
        .file
        .robots
        .iter()
        .map(|r| r.name.clone())
        .collect();
    Ok((Fleet { places }, own))
}

/// The timed run's figures of the loop (before the restart phase adds to what was seen).
struct Steady {
    expected: u64,
    on_time: u64,
    late: u64,
    periods: Vec<f64>,
}

async fn run(
    router: &mut RouterProcess,
    router_program: &Path,
    root: &str,
    session: &zenoh::Session,
    robots: usize,
    (rate_hz, seconds): (f64, f64),
    progress: Progress<'_>,
) -> Result<FleetBench, BenchError> {
    for service in [
        roam_sim::service::SERVICE_NAME,
        roam_localization::service::SERVICE_NAME,
        roam_controller::service::SERVICE_NAME,
    ] {
        wait_until_live(session, root, service, Duration::from_secs(30))
            .await
            .map_err(setup)?;
    }
    let client = Requester::new(session.clone(), Duration::from_secs(10));
    let control_key = keys::sim_control(root);
    let rss_before = rss_mib();
    let router_rss_before = rss_mib_of(router.pid());

    // Robots on free cells spread over the map; each drives to the robot half the fleet
    // away and back. The last one joins later.
    let (fleet, own) = places(robots)?;
    let starters = robots - 1;
    let joiner = Fleet::name(starters);
    // The built-in world's own robots leave first: the fleet is the bench's robots
    // alone, so `--robots` may be the sim's whole `max_robots` (1000).
    for name in own {
        client
            .request::<SimControl, SimStatus>(&control_key, Some(&SimControl::RemoveRobot { name }))
            .await?;
    }
    for k in 0..starters {
        client
            .request::<SimControl, SimStatus>(
                &control_key,
                Some(&SimControl::AddRobot {
                    name: Fleet::name(k),
                    at: fleet.places[k],
                }),
            )
            .await?;
    }
    // One lock-step step, so that every robot has an estimate before its mission: the
    // controller holds at most 64 missions for robots it has not heard of yet.
    let estimated = Arc::new(Mutex::new(std::collections::HashSet::new()));
    let estimates = {
        let estimated = estimated.clone();
        let root = root.to_owned();
        session
            .declare_subscriber(keys::robot_estimate_any(&root))
            .callback(move |sample| {
                if let Some(robot) = keys::robot_of(&root, sample.key_expr().as_str()) {
                    roam_runtime::lock(&estimated).insert(robot.to_owned());
                }
            })
            .await
            .map_err(setup)?
    };
    let waited = tokio::time::timeout(Duration::from_secs(30), async {
        while roam_runtime::lock(&estimated).len() < starters {
            let _ = client
                .request::<SimControl, SimStatus>(&control_key, Some(&SimControl::Step { n: 1 }))
                .await;
            tokio::time::sleep(Duration::from_millis(200)).await;
        }
    })
    .await;
    drop(estimates);
    if waited.is_err() {
        return Err(BenchError::Setup(format!(
            "only {} of {starters} robots were estimated",
            roam_runtime::lock(&estimated).len()
        )));
    }
    for k in 0..starters {
        session
            .put(
                keys::robot_mission(root, &Fleet::name(k)),
                encode(&fleet.mission(k)),
            )
            .await
            .map_err(setup)?;
    }

    let seen = Arc::new(Mutex::new(Seen::default()));
    let latest = Arc::new(AtomicU64::new(0));
    let clock_sub = {
        let (seen, latest) = (seen.clone(), latest.clone());
        session
            .declare_subscriber(keys::sim_clock(root))
            .callback(move |sample| {
                if let Ok(clock) = decode::<SimClock>(&sample.payload().to_bytes()) {
                    latest.fetch_max(clock.step, Ordering::AcqRel);
                    roam_runtime::lock(&seen)
                        .clocks
                        .push((clock.step, Instant::now()));
                }
            })
            .await
            .map_err(setup)?
    };
    let cmd_sub = {
        let (seen, latest) = (seen.clone(), latest.clone());
        let root = root.to_owned();
        session
            .declare_subscriber(keys::robot_command_any(&root))
            .callback(move |sample| {
                let now = Instant::now();
                let now_step = latest.load(Ordering::Acquire);
                let Ok(command) = decode::<RobotCommand>(&sample.payload().to_bytes()) else {
                    return;
                };
                let Some(step) = command.step else {
                    return;
                };
                let robot = keys::robot_of(&root, sample.key_expr().as_str())
                    .map(str::to_owned)
                    .unwrap_or_default();
                let mut seen = roam_runtime::lock(&seen);
                if seen.since.is_some_and(|since| now >= since) {
                    seen.again.entry(robot.clone()).or_insert(now);
                }
                seen.first.entry(robot).or_insert((step, now));
                if now_step <= step {
                    seen.on_time += 1;
                    *seen.on_time_at.entry(step).or_default() += 1;
                } else {
                    seen.late += 1;
                }
            })
            .await
            .map_err(setup)?
    };
    // The joiner's first range scan.
    let first_scan = Arc::new(OnceLock::new());
    let scan_sub = {
        let first_scan = first_scan.clone();
        session
            .declare_subscriber(keys::robot_ranges(root, &joiner))
            .callback(move |_| {
                let _ = first_scan.set(Instant::now());
            })
            .await
            .map_err(setup)?
    };

    let joiner_mission = fleet.mission(starters);
    let router_cpu_before = cpu_seconds_of(router.pid());
    let router_started = Instant::now();
    let (timed, added) = tokio::join!(
        run_sim_for(&client, &control_key, rate_hz, seconds, progress),
        join(
            &client,
            session,
            root,
            (&joiner, fleet.places[starters], &joiner_mission),
            Duration::from_secs_f64(seconds / 2.0),
        ),
    );
    let router_wall = router_started.elapsed().as_secs_f64();
    let router_cpu = match (router_cpu_before, cpu_seconds_of(router.pid())) {
        (Some(a), Some(b)) => b - a,
        _ => f64::NAN,
    };
    let TimedRun { end, wall, cpu } = timed?;
    let added = added?;
    // The last step's commands.
    tokio::time::sleep(Duration::from_millis(500)).await;
    let rss_after = rss_mib();
    let (router_rss, router_peak_rss) = (rss_mib_of(router.pid()), peak_rss_mib_of(router.pid()));
    let steady = steady(&roam_runtime::lock(&seen), robots);

    let restart = restart(
        router,
        router_program,
        &client,
        &control_key,
        rate_hz,
        (&seen, &latest),
        robots,
        progress,
    )
    .await?;
    drop(clock_sub);
    drop(cmd_sub);
    drop(scan_sub);

    let joined = roam_runtime::lock(&seen).first.get(&joiner).map(|f| f.1);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let pick = |q: f64| {
        steady
            .periods
            .get(((steady.periods.len().saturating_sub(1)) as f64 * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    let per_robot = |before: Option<f64>, after: Option<f64>| match (before, after) {
        (Some(a), Some(b)) => (b - a) / robots as f64,
        _ => f64::NAN,
    };
    Ok(FleetBench {
        robots,
        rate_hz,
        seconds: wall,
        steps: end.free_steps,
        sim_on_time_share: if end.free_steps == 0 {
            0.0
        } else {
            1.0 - end.late_steps as f64 / end.free_steps as f64
        },
        loop_on_time_share: share(steady.on_time, steady.expected),
        commands_expected: steady.expected,
        commands_on_time: steady.on_time,
        commands_late: steady.late,
        step_period_p50_ms: pick(0.5),
        step_period_p99_ms: pick(0.99),
        cpu_share: cpu / wall / cores as f64,
        cores,
        rss_per_robot_mib: per_robot(rss_before, rss_after),
        rss_mib: rss_after,
        peak_rss_mib: peak_rss_mib(),
        router_cpu_share: router_cpu / router_wall / cores as f64,
        router_cpu_us_per_robot_step: if end.free_steps == 0 {
            f64::NAN
        } else {
            router_cpu * 1e6 / (end.free_steps as f64 * robots as f64)
        },
        router_rss_mib: router_rss,
        router_peak_rss_mib: router_peak_rss,
        router_rss_per_robot_mib: per_robot(router_rss_before, router_rss),
        join_ms: match (first_scan.get(), joined) {
            (Some(&scan), Some(command)) => Some(ms(command.saturating_duration_since(scan))),
            _ => None,
        },
        join_from_add_ms: joined.map(|command| ms(command.saturating_duration_since(added))),
        restart_down_ms: ms(restart.down),
        restart_first_command_ms: restart.first.map(ms),
        restart_all_commanded_ms: restart.all.map(ms),
        restart_robots_commanded: restart.commanded,
        restart_steps_outside: restart.outside.0,
        restart_on_time_share_outside: share(restart.outside.1, restart.outside.0 * robots as u64),
        restart_steps_inside: restart.inside.0,
        restart_on_time_share_inside: share(restart.inside.1, restart.inside.0 * robots as u64),
    })
}

/// `part` over `whole`, 0 when there is no whole.
fn share(part: u64, whole: u64) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 / whole as f64
    }
}

/// The joiner, `delay` into the timed run: its mission first (the controller holds it
/// for the robot's first estimate), then the sim adds it. When the sim was asked.
async fn join(
    client: &Requester,
    session: &zenoh::Session,
    root: &str,
    (name, at, mission): (&str, [f64; 2], &Mission),
    delay: Duration,
) -> Result<Instant, BenchError> {
    tokio::time::sleep(delay).await;
    session
        .put(keys::robot_mission(root, name), encode(mission))
        .await
        .map_err(setup)?;
    let asked = Instant::now();
    client
        .request::<SimControl, SimStatus>(
            &keys::sim_control(root),
            Some(&SimControl::AddRobot {
                name: name.to_owned(),
                at,
            }),
        )
        .await?;
    Ok(asked)
}

/// The timed run's commands as seen so far.
fn steady(seen: &Seen, robots: usize) -> Steady {
    let last = seen.clocks.iter().map(|c| c.0).max().unwrap_or(0);
    // Every robot should have had a command for each step from its first to the last.
    let expected: u64 = seen
        .first
        .values()
        .map(|&(first, _)| last.saturating_sub(first) + 1)
        .sum::<u64>()
        + (robots.saturating_sub(seen.first.len()) as u64) * last;
    let mut periods: Vec<f64> = seen
        .clocks
        .windows(2)
        .filter(|w| w[1].0 == w[0].0 + 1)
        .map(|w| (w[1].1 - w[0].1).as_secs_f64() * 1000.0)
        .collect();
    periods.sort_by(f64::total_cmp);
    Steady {
        expected,
        on_time: seen.on_time,
        late: seen.late,
        periods,
    }
}

/// What the router's restart did.
struct Restart {
    down: Duration,
    first: Option<Duration>,
    all: Option<Duration>,
    commanded: usize,
    /// Steps, and the commands on time in them.
    outside: (u64, u64),
    inside: (u64, u64),
}

/// The restart phase: the sim runs again, the router is killed and started again on its
/// endpoint, and the bench waits until every robot is commanded again.
#[expect(clippy::too_many_arguments)]
async fn restart(
    router: &mut RouterProcess,
    router_program: &Path,
    client: &Requester,
    control_key: &str,
    rate_hz: f64,
    (seen, latest): (&Mutex<Seen>, &AtomicU64),
    robots: usize,
    progress: Progress<'_>,
) -> Result<Restart, BenchError> {
    let status: SimStatus = client
        .request(control_key, Some(&SimControl::Status))
        .await?;
    let from_step = latest.load(Ordering::Acquire) + 1;
    client
        .request::<SimControl, SimStatus>(
            control_key,
            Some(&SimControl::Resume {
                rate: rate_hz * status.step_s,
            }),
        )
        .await?;
    tokio::time::sleep(RESTART_LEAD).await;
    let kill_step = latest.load(Ordering::Acquire);
    let killed = Instant::now();
    router.kill();
    tokio::time::sleep(ROUTER_DOWN).await;
    let endpoint = router.endpoint.clone();
    *router = RouterProcess::spawn(router_program, &endpoint)?;
    let restarted = Instant::now();
    roam_runtime::lock(seen).since = Some(restarted);
    loop {
        let again = roam_runtime::lock(seen).again.len();
        progress(Done::of("router restart", "robots", again, robots));
        if again >= robots || restarted.elapsed() >= RECOVERY_LIMIT {
            break;
        }
        if let Some(status) = router.exited() {
            return Err(BenchError::Setup(format!(
                "the restarted router on {endpoint} exited ({status})"
            )));
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let recovered_step = latest.load(Ordering::Acquire);
    tokio::time::sleep(RESTART_TAIL).await;
    client
        .request::<SimControl, SimStatus>(control_key, Some(&SimControl::Pause))
        .await?;
    // The last step's commands.
    tokio::time::sleep(Duration::from_millis(500)).await;
    let last_step = latest.load(Ordering::Acquire);

    let seen = roam_runtime::lock(seen);
    let after = |t: &Instant| t.saturating_duration_since(restarted);
    let commanded = seen.again.len();
    // The steps from..=to and the commands on time for them.
    let count = |from: u64, to: u64| {
        if from > to {
            return (0, 0);
        }
        let on_time: u64 = seen.on_time_at.range(from..=to).map(|(_, n)| n).sum();
        (to - from + 1, on_time)
    };
    let inside = count(kill_step, recovered_step);
    let before = count(from_step, kill_step.saturating_sub(1));
    let tail = count(recovered_step + 1, last_step);
    Ok(Restart {
        down: restarted - killed,
        first: seen.again.values().min().map(after),
        all: (commanded >= robots)
            .then(|| seen.again.values().max().map(after))
            .flatten(),
        commanded,
        outside: (before.0 + tail.0, before.1 + tail.1),
        inside,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_experiments::progress::silent;

    #[tokio::test]
    async fn a_fleet_outside_the_sims_limit_is_refused_naming_it_before_anything_starts() {
        let most = roam_sim::sim::MAX_ROBOTS;
        for robots in [0, most + 1] {
            // No router program: a refusal that started anything would say so instead.
            let refused = fleet(robots, 10.0, 1.0, Path::new("/nonexistent/roam"), &silent)
                .await
                .expect_err("refused");
            assert!(
                refused.to_string().contains(&format!("1..={most}")),
                "{refused}"
            );
        }
    }
}
