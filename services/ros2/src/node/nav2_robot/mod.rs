//! A robot on Nav2 as roam's robot: the node stands in, on roam's keys, for the two
//! services roam's executive drives a robot through (localization and the controller),
//! and does their work with the robot's own Nav2.
//!
//! - **Estimates.** Each pose on the robot's pose topic
//!   (geometry_msgs/msg/PoseWithCovarianceStamped: AMCL's `/amcl_pose`) becomes a
//!   `position_estimate` on `<root>/robot/<id>/estimate`: the position, the covariance's
//!   x-y block as the CRB (paper 002 Eq. 5's place: AMCL's particle spread is the
//!   robot's own uncertainty) and its √trace as the PEB.
//! - **Missions.** Each `mission` on `<root>/robot/<id>/mission` becomes a goal of the
//!   robot's `follow_path` (nav2_msgs/action/FollowPath): the waypoints as a
//!   nav_msgs/Path (Nav2's controllers prune what is behind the robot), which preempts
//!   the previous goal as Nav2's
//!   controller server does (no stop in between). A mission without waypoints cancels
//!   the goal (the robot stops).
//! - **Status.** A `controller_status` on `<root>/robot/<id>/controller` after every pose
//!   and every change, as roam's controller sends it: `active` while the goal runs
//!   (waypoint and distance left from the pose along the path), `completed` when it
//!   succeeds, `stuck` when the server rejects the goal, aborts it or does not answer
//!   (the executive replans, as for a robot stuck in a potential field's minimum), and
//!   `halted_stale` when no pose came for `pose_timeout_s` (the goal is cancelled: a robot
//!   roam cannot see is held; the first pose after it sends the mission again).
//!
//! Each reason is logged. The executive, its window machine, the planner and the time
//! model's calibration are roam's own and unchanged: the calibration fits paper 000
//! Eq. 2 to what this robot drives, as for any robot.
mod config;
mod goal;
mod inputs;
mod state;
mod status;

use std::sync::Arc;

use roam_proto::controller::MissionState;
use roam_proto::keys;
use roam_runtime::Service;

use crate::names::Qos;
use crate::node::action_client::ActionClient;
use crate::node::error::Ros2Error;
use crate::node::output::Output;
use crate::node::sim_time::MissionClock;
use crate::types;

pub use config::Nav2Robot;
use state::Robot;

/// Declares robot `config`'s subscriptions and action client and drives it until the
/// service stops.
pub(crate) async fn declare(
    service: &Service,
    out: Arc<Output>,
    root: &str,
    config: Nav2Robot,
    mission_clock: MissionClock,
) -> Result<(), Ros2Error> {
    config.check().map_err(|reason| Ros2Error::Declare {
        what: "Nav2 robot",
        key: config.robot.clone(),
        reason,
    })?;
    let (pose, poses, pose_token) = out
        .subscribe(
            "pose subscription",
            &config.pose_topic,
            types::POSE_WITH_COVARIANCE_STAMPED,
            Qos::STREAM,
        )
        .await?;
    let (_, feedbacks, feedback_token) = out
        .subscribe(
            "feedback subscription",
            &format!("{}/_action/feedback", config.follow_path),
            types::FOLLOW_PATH_FEEDBACK_MESSAGE,
            Qos::STREAM,
        )
        .await?;
    let mission_key = keys::robot_mission(root, &config.robot);
    let missions = out
        .session()
        .declare_subscriber(mission_key.clone())
        .await
        .map_err(|e| Ros2Error::Declare {
            what: "mission subscriber",
            key: mission_key.clone(),
            reason: e.to_string(),
        })?;
    let tokens = vec![pose_token, feedback_token];
    let follow_path = ActionClient::declare(
        &out,
        &config.follow_path,
        types::FOLLOW_PATH_SEND_GOAL,
        types::FOLLOW_PATH_GET_RESULT,
    )
    .await?;
    tracing::info!(
        robot = %config.robot,
        pose = %pose.qualified_name,
        follow_path = %config.follow_path,
        "roam ros2: driving a Nav2 robot"
    );
    let robot = Robot {
        estimate_key: keys::robot_estimate(root, &config.robot),
        status_key: keys::robot_controller(root, &config.robot),
        out,
        follow_path,
        config,
        mission_clock,
        mission: None,
        goal: None,
        state: MissionState::Idle,
        position: None,
        last_pose: None,
        step: 0,
        steps: 0,
        peb_m: None,
        distance_to_goal: None,
    };
    let cancel = service.cancel_token();
    service.spawn(async move {
        let _tokens = tokens;
        robot.run(poses, feedbacks, missions, cancel).await;
    });
    Ok(())
}
