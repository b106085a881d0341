//! The timed run: the fleet added, its missions put, the sim run at its rate while a
//! robot joins, then the restart phase; and the figures of it all.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use roam_experiments::progress::Progress;
use roam_proto::sim::{RobotCommand, SimClock, SimControl, SimStatus};
use roam_proto::{decode, encode, keys};
use roam_runtime::Requester;
use roam_stack::stack::wait_until_live;

use super::join::join;
use super::places::{places, Fleet};
use super::report::FleetBench;
use super::restart::restart;
use super::router::RouterProcess;
use super::seen::{share, steady, Seen};
use crate::process::{cpu_seconds_of, peak_rss_mib, peak_rss_mib_of, rss_mib, rss_mib_of};
use crate::sim::{run_sim_for, TimedRun};
use crate::{ms, setup, BenchError};

pub(super) async fn run(
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
        sim_on_time_share: end.on_time_share(),
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
