//! The controller's status message from a decision: one function for the service (which
//! publishes it) and the batch experiments (which hand it to the executive's window
//! machine in process), so both say the same.

use roam_proto::controller::ControllerStatus;
use roam_proto::localization::PositionEstimate;

use crate::controller::Decision;

/// The status of `robot`'s mission `mission` (of `waypoints` waypoints) after
/// `decision`, made on `estimate`.
pub fn controller_status(
    robot: &str,
    mission: &str,
    waypoints: usize,
    decision: &Decision,
    estimate: Option<&PositionEstimate>,
) -> ControllerStatus {
    ControllerStatus {
        robot: robot.to_owned(),
        mission: Some(mission.to_owned()),
        state: decision.status,
        waypoint: decision.waypoint,
        waypoints,
        distance_left_m: Some(decision.distance_left_m),
        steps: decision.steps,
        estimate_step: estimate.map(|e| e.step),
        peb_m: estimate.and_then(|e| e.peb_m),
        omega_deg: decision.omega_deg,
        z_isa: decision.z_isa,
        u: decision.u,
    }
}
