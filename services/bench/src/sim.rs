//! `roam bench sim`: many robots at a fixed sim rate, publishing their sensors.
//!
//! A router and the sim service run in this process on the built-in world; a client
//! adds `robots` robots on free cells spread over the map, resumes the sim at the real-
//! time factor that gives `rate_hz` steps per second, subscribes to every robot's
//! ranges, and lets it run for `seconds`. The sim counts a free-running step as late
//! when its messages are not all out before the next step is due.
//!
//! `cpu_share` is the process's CPU time (user + system, from `/proc/self/stat`, in
//! Linux's 100 Hz clock ticks) over wall time and cores: 1.0 would be every core busy.

use std::time::{Duration, Instant};

use roam_proto::keys;
use roam_proto::sim::{SimControl, SimStatus};
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::{Requester, SessionArgs};
use roam_sim::service::SimConfig;
use serde::Serialize;
use tokio_util::sync::CancellationToken;

use crate::process::process_cpu_seconds;
use crate::{setup, BenchError};
use roam_experiments::progress::{Done, Progress};
use roam_stack::router::Router;
use roam_stack::stack::wait_until_live;

#[derive(Debug, Clone, Serialize)]
pub struct SimBench {
    pub robots: usize,
    pub rate_hz: f64,
    pub seconds: f64,
    pub steps: u64,
    pub on_time_share: f64,
    pub cpu_share: f64,
    /// Range scans received by the subscriber, and how many the steps should give.
    pub ranges_received: u64,
    pub ranges_expected: u64,
}

/// Runs the bench; `progress` each second of the timed run (stage `running`).
pub async fn sim(
    robots: usize,
    rate_hz: f64,
    seconds: f64,
    progress: Progress<'_>,
) -> Result<SimBench, BenchError> {
    let router = Router::on_loopback().await.map_err(setup)?;
    let root = "roam-bench-sim".to_owned();
    let cancel = CancellationToken::new();
    let config = SimConfig {
        service: ServiceConfig::at(root.clone()),
        rate: None,
        ..SimConfig::default()
    };
    let zenoh_config = SessionArgs::client_of(&router.endpoint)
        .zenoh_config(None)
        .map_err(setup)?;
    let token = cancel.clone();
    let service =
        tokio::spawn(async move { roam_sim::service::run(config, zenoh_config, token).await });
    let result = async {
        wait_until_live(
            &router.session,
            &root,
            roam_sim::service::SERVICE_NAME,
            Duration::from_secs(30),
        )
        .await
        .map_err(setup)?;
        let session = roam_runtime::session::open(
            SessionArgs::client_of(&router.endpoint)
                .zenoh_config(None)
                .map_err(setup)?,
        )
        .await
        .map_err(setup)?;
        let client = Requester::new(session.clone(), Duration::from_secs(10));
        let control_key = keys::sim_control(&root);

        // Robots on free cells, spread over the map.
        let (places, _) = crate::spread::spread(robots, false)?;
        for (k, at) in places.into_iter().enumerate() {
            let request = SimControl::AddRobot {
                name: format!("bench-{k}"),
                at,
            };
            client
                .request::<SimControl, SimStatus>(&control_key, Some(&request))
                .await?;
        }
        let counter = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
        let subscriber = {
            let counter = counter.clone();
            session
                .declare_subscriber(keys::robot_ranges_any(&root))
                .callback(move |_| {
                    counter.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                })
                .await
                .map_err(setup)?
        };
        let TimedRun { end, wall, cpu } =
            run_sim_for(&client, &control_key, rate_hz, seconds, progress).await?;
        // Let the last publications arrive.
        tokio::time::sleep(Duration::from_millis(300)).await;
        drop(subscriber);
        let _ = session.close().await;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as f64;
        let total_robots = end.robots.len() as u64;
        Ok(SimBench {
            robots,
            rate_hz,
            seconds: wall,
            steps: end.free_steps,
            on_time_share: end.on_time_share(),
            cpu_share: cpu / wall / cores,
            ranges_received: counter.load(std::sync::atomic::Ordering::Relaxed),
            ranges_expected: end.free_steps * total_robots,
        })
    }
    .await;
    cancel.cancel();
    let _ = tokio::time::timeout(Duration::from_secs(5), service).await;
    router.close().await;
    result
}

/// What [`run_sim_for`] measured.
pub(crate) struct TimedRun {
    /// The sim's status when it was paused again.
    pub end: SimStatus,
    /// Wall-clock seconds from the resume to the pause.
    pub wall: f64,
    /// CPU seconds this process used meanwhile (NaN off Linux).
    pub cpu: f64,
}

/// Resumes the sim at `rate_hz` steps per wall second, lets it run `seconds`, pauses
/// it, and says what it did meanwhile: the window every sim-driven benchmark times.
/// `progress` after each whole second of it (stage `running`, in seconds).
pub(crate) async fn run_sim_for(
    client: &Requester,
    control_key: &str,
    rate_hz: f64,
    seconds: f64,
    progress: Progress<'_>,
) -> Result<TimedRun, roam_runtime::ClientError> {
    let status: SimStatus = client
        .request(control_key, Some(&SimControl::Status))
        .await?;
    // The sim's rate is a real-time factor: steps of `step_s` sim seconds.
    let factor = rate_hz * status.step_s;
    let cpu_before = process_cpu_seconds();
    let started = Instant::now();
    client
        .request::<SimControl, SimStatus>(control_key, Some(&SimControl::Resume { rate: factor }))
        .await?;
    wait_reporting(started, seconds, progress).await;
    let end: SimStatus = client
        .request(control_key, Some(&SimControl::Pause))
        .await?;
    let wall = started.elapsed().as_secs_f64();
    let cpu = match (cpu_before, process_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => f64::NAN,
    };
    Ok(TimedRun { end, wall, cpu })
}

/// Sleeps until `seconds` after `started`, waking each second to report the whole
/// seconds gone: the timed window is the same as one sleep's, to the timer's precision.
async fn wait_reporting(started: Instant, seconds: f64, progress: Progress<'_>) {
    let length = Duration::from_secs_f64(seconds);
    let whole = seconds.ceil() as usize;
    loop {
        let left = length.saturating_sub(started.elapsed());
        if left.is_zero() {
            break;
        }
        tokio::time::sleep(left.min(Duration::from_secs(1))).await;
        let gone = (started.elapsed().as_secs_f64().floor() as usize).min(whole);
        progress(Done::of("running", "seconds", gone, whole));
    }
    progress(Done::of("running", "seconds", whole, whole));
}
