//! `roam bench fleet`: many robots in closed loop through Zenoh.
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

mod join;
mod places;
mod report;
mod restart;
mod router;
mod run;
mod seen;

use std::path::Path;
use std::time::Duration;

use roam_controller::service::ControllerConfig;
use roam_localization::service::LocalizationConfig;
use roam_runtime::service_config::ServiceConfig;
use roam_runtime::SessionArgs;
use roam_sim::service::SimConfig;

use crate::{setup, BenchError};
use roam_stack::roles::Role;
use tokio_util::sync::CancellationToken;

use roam_experiments::progress::Progress;

pub use report::FleetBench;
pub use restart::{RECOVERY_LIMIT, RESTART_LEAD, RESTART_TAIL, ROUTER_DOWN};
use router::start_router;
use run::run;

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
    // The loop's three roles, each a client of the router, run as the stack runs them.
    let roles = [
        Role::from(SimConfig {
            service: ServiceConfig::at(root.clone()),
            rate: None,
            ..SimConfig::default()
        }),
        Role::from(LocalizationConfig {
            service: ServiceConfig::at(root.clone()),
            publish_peb_layer: false,
            ..LocalizationConfig::default()
        }),
        Role::from(ControllerConfig {
            service: ServiceConfig::at(root.clone()),
            ..ControllerConfig::default()
        }),
    ];
    let mut services = tokio::task::JoinSet::new();
    for role in roles {
        services.spawn(role.run(client_config()?, cancel.clone()));
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
