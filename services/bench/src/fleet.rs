//! `roam bench fleet`: many robots in closed loop through Zenoh (issue 16).
//!
//! A router, the sim, localization and the APF controller run in this process on the
//! built-in world, as in `roam stack`. A client adds `robots` robots on free cells spread
//! over the map and gives each a mission across the map and back (waypoints, paper
//! 002's controller), then resumes the sim at `rate_hz` steps per second for `seconds`.
//! Every step the loop is sim → `ranges` → localization → `estimate` → controller →
//! `cmd` → sim, for every robot, over Zenoh.
//!
//! **On time.** A command answers the estimate of step k (it carries k); it is on time
//! when it reaches the bench's subscriber before the sim's clock for step k + 1 does
//! (the sim applies a command at the next step, so a later one misses its step). Both
//! arrive through the same router as at the sim, so the order seen here is the order
//! the sim sees, to within the router's fan-out. `loop_on_time_share` is the commands
//! on time over the robots × steps that should have had one (steps after the robots'
//! first estimates); `sim_on_time_share` is the sim's own count of steps whose messages
//! were out before the next step was due.
//!
//! `cpu_share` is the process's CPU time over wall time and cores (1.0: every core
//! busy); `rss_per_robot_mib` the resident memory the robots added (after minus before
//! adding them, over the robots).

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
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

use crate::{setup, BenchError};
use tokio_util::sync::CancellationToken;

use crate::process::{peak_rss_mib, rss_mib};
use crate::sim::{run_sim_for, TimedRun};
use roam_experiments::progress::Progress;
use roam_stack::router::Router;
use roam_stack::stack::wait_until_live;

#[derive(Debug, Clone, Serialize)]
pub struct FleetBench {
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
    pub cpu_share: f64,
    pub cores: usize,
    pub rss_per_robot_mib: f64,
    pub rss_mib: Option<f64>,
    pub peak_rss_mib: Option<f64>,
}

/// What the subscribers saw.
#[derive(Debug, Default)]
struct Seen {
    /// The latest clock step, and when each clock arrived.
    clocks: Vec<(u64, Instant)>,
    /// Per robot, the first step it had a command for.
    first: HashMap<String, u64>,
    on_time: u64,
    late: u64,
}

/// Runs the bench; `progress` each second of the timed run (stage `running`).
pub async fn fleet(
    robots: usize,
    rate_hz: f64,
    seconds: f64,
    progress: Progress<'_>,
) -> Result<FleetBench, BenchError> {
    let router = Router::on_loopback().await.map_err(setup)?;
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
        &router,
        &root,
        &client_config()?,
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
    router.close().await;
    result
}

async fn run(
    router: &Router,
    root: &str,
    client_config: &zenoh::Config,
    robots: usize,
    (rate_hz, seconds): (f64, f64),
    progress: Progress<'_>,
) -> Result<FleetBench, BenchError> {
    for service in [
        roam_sim::service::SERVICE_NAME,
        roam_localization::service::SERVICE_NAME,
        roam_controller::service::SERVICE_NAME,
    ] {
        wait_until_live(&router.session, root, service, Duration::from_secs(30))
            .await
            .map_err(setup)?;
    }
    let session = roam_runtime::session::open(client_config.clone())
        .await
        .map_err(setup)?;
    let client = Requester::new(session.clone(), Duration::from_secs(10));
    let control_key = keys::sim_control(root);
    let rss_before = rss_mib();

    // Robots on free cells spread over the map; each drives to the robot half the fleet
    // away and back.
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
    let places: Vec<[f64; 2]> = (0..robots)
        .map(|k| {
            let i = free[k * stride];
            let (x, y) = cell_center(&meta, i % width, i / width);
            [x, y]
        })
        .collect();
    // The built-in world's own robots leave first: the fleet is the bench's robots
    // alone, so `--robots` may be the sim's whole `max_robots` (1000).
    for start in &scenario.file.robots {
        client
            .request::<SimControl, SimStatus>(
                &control_key,
                Some(&SimControl::RemoveRobot {
                    name: start.name.clone(),
                }),
            )
            .await?;
    }
    for (k, &at) in places.iter().enumerate() {
        client
            .request::<SimControl, SimStatus>(
                &control_key,
                Some(&SimControl::AddRobot {
                    name: format!("fleet-{k}"),
                    at,
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
        while roam_runtime::lock(&estimated).len() < robots {
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
            "only {} of {robots} robots were estimated",
            roam_runtime::lock(&estimated).len()
        )));
    }
    for (k, &at) in places.iter().enumerate() {
        let name = format!("fleet-{k}");
        let mission = Mission {
            after_step: None,
            robot: name.clone(),
            id: format!("bench-{k}"),
            waypoints: vec![places[(k + robots / 2) % robots], at],
            recovery: false,
        };
        session
            .put(keys::robot_mission(root, &name), encode(&mission))
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
                seen.first.entry(robot).or_insert(step);
                if now_step <= step {
                    seen.on_time += 1;
                } else {
                    seen.late += 1;
                }
            })
            .await
            .map_err(setup)?
    };

    let TimedRun { end, wall, cpu } =
        run_sim_for(&client, &control_key, rate_hz, seconds, progress).await?;
    // The last step's commands.
    tokio::time::sleep(Duration::from_millis(500)).await;
    let rss_after = rss_mib();
    drop(clock_sub);
    drop(cmd_sub);
    let _ = session.close().await;

    let seen = roam_runtime::lock(&seen);
    let last = seen.clocks.iter().map(|c| c.0).max().unwrap_or(0);
    // Every robot should have had a command for each step from its first to the last.
    let expected: u64 = seen
        .first
        .values()
        .map(|&first| last.saturating_sub(first) + 1)
        .sum::<u64>()
        + (robots.saturating_sub(seen.first.len()) as u64) * last;
    let mut periods: Vec<f64> = seen
        .clocks
        .windows(2)
        .filter(|w| w[1].0 == w[0].0 + 1)
        .map(|w| (w[1].1 - w[0].1).as_secs_f64() * 1000.0)
        .collect();
    periods.sort_by(f64::total_cmp);
    let pick = |q: f64| {
        periods
            .get(((periods.len().saturating_sub(1)) as f64 * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
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
        loop_on_time_share: if expected == 0 {
            0.0
        } else {
            seen.on_time as f64 / expected as f64
        },
        commands_expected: expected,
        commands_on_time: seen.on_time,
        commands_late: seen.late,
        step_period_p50_ms: pick(0.5),
        step_period_p99_ms: pick(0.99),
        cpu_share: cpu / wall / cores as f64,
        cores,
        rss_per_robot_mib: match (rss_before, rss_after) {
            (Some(a), Some(b)) => (b - a) / robots as f64,
            _ => f64::NAN,
        },
        rss_mib: rss_after,
        peak_rss_mib: peak_rss_mib(),
    })
}
