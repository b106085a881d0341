//! A day whose tasks cannot be kept is refused when `roam mission` loads it, before the
//! robot moves: through Zenoh, the executive fetches the map server's world, checks the
//! day against it, and stops with the tasks and the seconds missing named.

use std::time::Duration;

use roam_mission::config::ExecutiveConfig;
use roam_mission::service::MissionConfig;
use roam_mission::tasks::Task;
use roam_runtime::service_config::ServiceConfig;
use roam_tests::{repo_path, Harness};

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_day_whose_tasks_cannot_be_reached_in_time_is_refused_naming_them() {
    let harness = Harness::start().await;
    let _map_server = harness
        .start_role(roam_map_server::MapServerConfig {
            map: Some(repo_path("config/scenarios/day.yaml")),
            ..harness.map_server_config()
        })
        .await;
    // goal1 to goal2 is some 30 s of driving; 3 s between them cannot be kept.
    let task = |name: &str, at: [f64; 2], start_s: f64| Task {
        name: name.into(),
        at,
        start_s,
        duration_s: 5.0,
    };
    let mission = harness
        .start_role(MissionConfig {
            service: ServiceConfig::at(harness.root.clone()),
            executive: ExecutiveConfig {
                tasks: vec![
                    task("goal1", [-2.0, 4.0], 75.0),
                    task("goal2", [6.0, -7.0], 83.0),
                ],
                ..ExecutiveConfig::default()
            },
            ..MissionConfig::default()
        })
        .await;
    // The refusal comes as soon as the world is fetched.
    tokio::time::sleep(Duration::from_secs(2)).await;
    let (_, outcome) = mission.stop().await;
    let error = outcome.expect_err("the day is refused");
    assert!(error.contains("\"goal2\""), "{error}");
    assert!(error.contains("\"goal1\""), "{error}");
    assert!(error.contains("missing"), "{error}");
}
