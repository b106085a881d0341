//! Missions checked, held or queued until their robot is ready, and installed.

use std::time::Instant;

use roam_proto::controller::{
    ControllerStatus, Mission, MissionState, MAX_MISSION_ID_BYTES, MAX_WAYPOINTS,
};
use roam_proto::{excerpt, keys};
use roam_runtime::{limited_warn, routing};

use crate::controller::Controller;

use super::shared::{ControlledRobot, ControllerShared, MAX_ROBOTS};

/// Checks a mission before it replaces the robot's current one.
fn check_mission(mission: &Mission) -> Result<(), String> {
    if mission.id.len() > MAX_MISSION_ID_BYTES {
        return Err(format!(
            "the id '{}' is {} bytes; at most {MAX_MISSION_ID_BYTES} (max_mission_id_bytes)",
            excerpt(&mission.id),
            mission.id.len()
        ));
    }
    if mission.waypoints.len() > MAX_WAYPOINTS {
        return Err(format!(
            "{} waypoints; a mission holds at most {MAX_WAYPOINTS} (max_waypoints)",
            mission.waypoints.len()
        ));
    }
    if let Some(bad) = mission
        .waypoints
        .iter()
        .find(|w| !(w[0].is_finite() && w[1].is_finite()))
    {
        return Err(format!("waypoint {bad:?} is not a finite point"));
    }
    Ok(())
}

pub(super) fn on_mission(state: &ControllerShared, key: &str, mission: Mission) {
    let robot = match routing::robot_for(&state.root, key, &mission.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "mission refused: {e}"),
    };
    let id = excerpt(&mission.id);
    if let Err(e) = check_mission(&mission) {
        return limited_warn!(state.warnings, key, %robot, %id, "mission refused: {e}");
    }
    if !state.allowed.is_empty() && !state.allowed.iter().any(|r| r == robot) {
        return limited_warn!(
            state.warnings, key, %robot, %id,
            "mission refused: this controller drives only {:?} (robots)", state.allowed
        );
    }
    if !state.is_present(robot) {
        // Not in the scenario and not heard of yet (a robot just added to the sim, a
        // real robot before its first scan): the mission waits for the robot's first estimate, in a small table of its own,
        // so missions for robots that do not exist never take a driving slot.
        tracing::debug!(%robot, %id, "mission held until the robot's first estimate");
        state.hold(robot, mission);
        return;
    }
    if state.waits(robot, &mission) {
        // Decided on an estimate not answered yet: it starts once it is (the queue
        // holds one mission per robot the world has, the latest).
        roam_runtime::lock(&state.queued).insert(robot.to_owned(), mission);
        return;
    }
    roam_runtime::lock(&state.queued).remove(robot);
    install_mission(state, robot, &mission);
}

/// Makes `mission` the robot's current one and publishes its first status.
pub(super) fn install_mission(state: &ControllerShared, robot: &str, mission: &Mission) {
    let mut robots = state.robots();
    if robots.len() >= MAX_ROBOTS && !robots.contains_key(robot) {
        return limited_warn!(
            state.warnings, robot, %robot,
            "mission refused: this controller already drives {MAX_ROBOTS} robots (max_robots)"
        );
    }
    let driven = robots
        .entry(robot.to_owned())
        .or_insert_with(|| ControlledRobot {
            controller: Controller::new(
                state.params.clone(),
                state.obstacles.clone(),
                state.information.clone(),
            ),
            mission: String::new(),
            waypoints: 0,
            last_estimate: Instant::now(),
            stale: false,
            last: None,
        });
    if mission.recovery {
        driven.controller.set_recovery(mission.waypoints.clone());
    } else {
        driven.controller.set_mission(mission.waypoints.clone());
    }
    driven.mission = mission.id.clone();
    driven.waypoints = mission.waypoints.len();
    driven.last_estimate = Instant::now();
    driven.stale = false;
    let state_now = if mission.waypoints.is_empty() {
        MissionState::Idle
    } else {
        MissionState::Active
    };
    let status = ControllerStatus {
        robot: robot.to_owned(),
        mission: Some(mission.id.clone()),
        state: state_now,
        waypoint: (!mission.waypoints.is_empty()).then_some(0),
        waypoints: driven.waypoints,
        distance_left_m: None,
        steps: 0,
        estimate_step: None,
        peb_m: None,
        omega_deg: 0.0,
        z_isa: 0.0,
        u: [0.0, 0.0],
    };
    driven.last = Some(status.clone());
    drop(robots);
    tracing::info!(%robot, id = %excerpt(&mission.id), waypoints = mission.waypoints.len(), "mission set");
    if mission.waypoints.is_empty() {
        // An empty mission stops the robot now, not at its next estimate.
        state.command(robot, [0.0, 0.0], None);
    }
    state.put(&keys::robot_controller(&state.root, robot), &status);
}
