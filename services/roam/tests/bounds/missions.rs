//! Strangers' missions: huge ones, ones for robots that do not exist, ones with huge
//! ids. The controller and the view keep none of them, and nothing is commanded.

use std::time::Duration;

use roam_proto::controller::Mission;
use roam_proto::{encode, keys};

/// Missions of ten million waypoints (about 60 MB each) put at once.
pub(crate) const HUGE_MISSIONS: usize = 3;
/// Missions for robots that do not exist.
pub(crate) const GHOSTS: usize = 1000;

pub(crate) async fn attack(session: &zenoh::Session, root: &str) -> usize {
    let huge = encode(&Mission {
        after_step: None,
        robot: "robot".into(),
        id: "huge".into(),
        waypoints: vec![[1.234_567_890_123, -9.876_543_210_987]; 10_000_000],
        recovery: false,
    });
    for _ in 0..HUGE_MISSIONS {
        session
            .put(keys::robot_mission(root, "robot"), huge.clone())
            .await
            .expect("put");
    }
    drop(huge);
    for i in 0..GHOSTS {
        let ghost = format!("ghost-{i}");
        let mission = Mission {
            after_step: None,
            robot: ghost.clone(),
            id: format!("ghost-mission-{i}"),
            waypoints: vec![[1.0, 1.0]],
            recovery: false,
        };
        session
            .put(keys::robot_mission(root, &ghost), encode(&mission))
            .await
            .expect("put");
    }
    let long_id = Mission {
        after_step: None,
        robot: "robot".into(),
        id: "i".repeat(1_000_000),
        waypoints: vec![[1.0, 1.0]],
        recovery: false,
    };
    session
        .put(keys::robot_mission(root, "robot"), encode(&long_id))
        .await
        .expect("put");
    // What the controller sends for any robot from now on: nothing, since none of these
    // missions was taken.
    let commands = session
        .declare_subscriber(keys::robot_command_any(root))
        .await
        .expect("subscriber");
    let statuses = session
        .declare_subscriber(keys::robot_controller_any(root))
        .await
        .expect("subscriber");
    tokio::time::sleep(Duration::from_secs(3)).await;
    let mut acted = 0;
    while let Ok(Some(_)) = commands.try_recv() {
        acted += 1;
    }
    while let Ok(Some(_)) = statuses.try_recv() {
        acted += 1;
    }
    acted
}
