//! An estimate answered: the robot's command and status, and the missions it frees.

use std::time::Instant;

use roam_proto::controller::ControllerStatus;
use roam_proto::keys;
use roam_proto::localization::PositionEstimate;
use roam_runtime::{limited_warn, routing};

use crate::controller::{Decision, MissionState};

use super::missions::install_mission;
use super::shared::{ControlledRobot, ControllerShared};

fn status_of(
    robot: &str,
    driven: &ControlledRobot,
    decision: &Decision,
    estimate: Option<&PositionEstimate>,
) -> ControllerStatus {
    crate::status::controller_status(robot, &driven.mission, driven.waypoints, decision, estimate)
}

pub(super) fn on_estimate(state: &ControllerShared, key: &str, estimate: PositionEstimate) {
    let robot = match routing::robot_for(&state.root, key, &estimate.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "ignoring an estimate: {e}"),
    };
    state.note_seen(robot);
    if let Some(mission) = state.take_held(robot) {
        install_mission(state, robot, &mission);
    }
    if let Some(mission) = state.take_queued(robot, estimate.step, true) {
        install_mission(state, robot, &mission);
    }
    roam_runtime::lock(&state.answered).insert(robot.to_owned(), estimate.step);
    let (status, u) = {
        let mut robots = state.robots();
        let Some(driven) = robots.get_mut(robot) else {
            return;
        };
        driven.last_estimate = Instant::now();
        driven.stale = false;
        let decision = driven.controller.update(estimate.position, estimate.peb_m);
        let status = status_of(robot, driven, &decision, Some(&estimate));
        driven.last = Some(status.clone());
        let u = match decision.status {
            MissionState::Idle => None,
            _ => Some(decision.u),
        };
        (status, u)
    };
    if let Some(u) = u {
        state.command(robot, u, Some(estimate.step));
    }
    state.put(&keys::robot_controller(&state.root, robot), &status);
    if let Some(mission) = state.take_queued(robot, estimate.step, false) {
        install_mission(state, robot, &mission);
    }
}
