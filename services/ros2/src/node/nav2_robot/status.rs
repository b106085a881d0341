//! The controller's report the robot sends, from its last pose along the mission.

use roam_proto::controller::{ControllerStatus, MissionState};
use roam_proto::encode;
use roam_runtime::Delivery;

use super::state::Robot;

impl Robot {
    /// The controller's report, from the last pose along the mission's waypoints.
    pub(super) async fn publish_status(&self) {
        let waypoints = self.mission.as_ref().map_or(&[][..], |m| &m.waypoints[..]);
        let (waypoint, distance_left_m) = match (self.state, self.position) {
            (MissionState::Active, Some(at)) if !waypoints.is_empty() => {
                let (index, left) = ahead(at, waypoints);
                (Some(index), Some(self.distance_to_goal.unwrap_or(left)))
            }
            (MissionState::Completed, _) => (None, Some(0.0)),
            _ => (None, None),
        };
        let status = ControllerStatus {
            robot: self.config.robot.clone(),
            mission: self.mission.as_ref().map(|m| m.id.clone()),
            state: self.state,
            waypoint,
            waypoints: waypoints.len(),
            distance_left_m,
            steps: self.steps,
            estimate_step: (self.step > 0).then_some(self.step),
            peb_m: self.peb_m,
            omega_deg: 0.0,
            z_isa: 0.0,
            u: [0.0, 0.0],
        };
        roam_runtime::publish_bytes(
            self.out.session(),
            &self.status_key,
            encode(&status),
            Delivery::Reliable,
        )
        .await;
    }
}

/// The waypoint ahead of a robot at `at` (the one after the nearest) and the distance
/// left along the path from there.
fn ahead(at: [f64; 2], waypoints: &[[f64; 2]]) -> (usize, f64) {
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let nearest = waypoints
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| dist(at, **a).total_cmp(&dist(at, **b)))
        .map_or(0, |(i, _)| i);
    let index = (nearest + 1).min(waypoints.len() - 1);
    let legs: f64 = waypoints[index..]
        .windows(2)
        .map(|w| dist(w[0], w[1]))
        .sum();
    (index, dist(at, waypoints[index]) + legs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_waypoint_ahead_and_the_distance_left() {
        let path = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 2.0]];
        let (index, left) = ahead([0.9, 0.0], &path);
        assert_eq!(index, 2);
        assert!((left - (1.1 + 2.0)).abs() < 1e-12);
        assert_eq!(ahead([2.0, 2.0], &path), (3, 0.0));
    }
}
