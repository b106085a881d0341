//! The robot's FollowPath goals: sent, followed to their end in a task of their own,
//! cancelled.

use std::time::Duration;

use roam_proto::controller::{Mission, MissionState};
use tokio::sync::mpsc;

use crate::convert;
use crate::msg::{
    FollowPathGoal, FollowPathResult, GetResultResponse, GoalState, SendGoalRequest, Uuid,
};

use super::state::{GoalEvent, Robot};

/// How long a goal's result is waited for at most (a path a robot drives for an hour).
const RESULT_WITHIN: Duration = Duration::from_secs(3600);

impl Robot {
    /// Sends `mission` to FollowPath and waits for its result in a task of its own.
    pub(super) fn send(&self, mission: &Mission, events: &mpsc::Sender<GoalEvent>) {
        let goal_id = Uuid {
            uuid: random_uuid(),
        };
        // The waypoints as planned: Nav2's controllers prune the part of a path behind
        // the robot themselves (the robot's projection onto it), as roam's controller
        // follows it from its projection.
        let waypoints = &mission.waypoints;
        let request = SendGoalRequest {
            goal_id,
            goal: FollowPathGoal {
                path: convert::path(waypoints, crate::node::services::now()),
                controller_id: self.config.controller_id.clone(),
                goal_checker_id: self.config.goal_checker_id.clone(),
                progress_checker_id: String::new(),
            },
        };
        let (client, events, id) = (self.follow_path.clone(), events.clone(), mission.id.clone());
        let within = Duration::from_secs_f64(self.config.answer_timeout_s);
        tokio::spawn(async move {
            let ended = |state, why: String| GoalEvent::Ended {
                mission: id.clone(),
                state,
                why,
            };
            let accepted = match client.send_goal(&request, within).await {
                Ok(r) if r.accepted => r,
                Ok(_) => {
                    let why = "follow_path rejected the goal".to_owned();
                    let _ = events.send(ended(MissionState::Stuck, why)).await;
                    return;
                }
                Err(why) => {
                    let _ = events.send(ended(MissionState::Stuck, why)).await;
                    return;
                }
            };
            let _ = accepted;
            let _ = events
                .send(GoalEvent::Accepted {
                    mission: id.clone(),
                    goal: goal_id,
                })
                .await;
            let event = match client
                .get_result::<GetResultResponse<FollowPathResult>>(goal_id, RESULT_WITHIN)
                .await
            {
                Ok(r) if r.status == GoalState::Succeeded as i8 => {
                    ended(MissionState::Completed, String::new())
                }
                Ok(r) => ended(
                    MissionState::Stuck,
                    format!(
                        "follow_path ended the goal with status {} (error {}: {})",
                        r.status,
                        r.result.error_code,
                        roam_proto::excerpt::excerpt_n(&r.result.error_msg, 200)
                    ),
                ),
                Err(why) => ended(MissionState::Stuck, why),
            };
            let _ = events.send(event).await;
        });
    }

    pub(super) async fn on_goal_event(&mut self, event: GoalEvent) {
        let current = self.mission.as_ref().map(|m| m.id.as_str());
        match event {
            GoalEvent::Accepted { mission, goal } if Some(mission.as_str()) == current => {
                self.goal = Some(goal);
            }
            GoalEvent::Ended {
                mission,
                state,
                why,
            } if Some(mission.as_str()) == current && self.state == MissionState::Active => {
                self.goal = None;
                if !why.is_empty() {
                    tracing::warn!(robot = %self.config.robot, %mission, "roam ros2: the Nav2 robot's mission ended {state:?}: {why}");
                }
                self.state = state;
                self.publish_status().await;
            }
            // A goal accepted after the robot was held, or of a mission since replaced by
            // an empty one: cancelled (a newer goal preempts it otherwise).
            GoalEvent::Accepted { goal, .. } if self.state != MissionState::Active => {
                self.cancel_this(goal)
            }
            GoalEvent::Accepted { .. } => {}
            GoalEvent::Ended { .. } => {}
        }
    }

    pub(super) fn cancel_goal(&mut self) {
        if let Some(goal) = self.goal.take() {
            self.cancel_this(goal);
        }
    }

    fn cancel_this(&self, goal: Uuid) {
        let (client, within) = (
            self.follow_path.clone(),
            Duration::from_secs_f64(self.config.answer_timeout_s),
        );
        let robot = self.config.robot.clone();
        tokio::spawn(async move {
            if let Err(e) = client.cancel(goal, within).await {
                tracing::warn!(%robot, "roam ros2: cancelling the Nav2 robot's goal: {e}");
            }
        });
    }
}

/// A goal id: 128 random bits, as rclcpp's.
fn random_uuid() -> [u8; 16] {
    let hex = roam_planner::token::random_hex128();
    let mut uuid = [0u8; 16];
    for (i, byte) in uuid.iter_mut().enumerate() {
        *byte = hex
            .get(2 * i..2 * i + 2)
            .and_then(|h| u8::from_str_radix(h, 16).ok())
            .unwrap_or(0);
    }
    uuid
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn goal_ids_are_random() {
        assert_ne!(random_uuid(), random_uuid());
    }
}
