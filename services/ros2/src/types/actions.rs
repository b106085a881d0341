//! Nav2's two actions (ComputePathToPose, FollowPath): their names and the parts rosidl
//! generates for each.

use super::def::Base::{Bool, Int8, Nested};
use super::def::{f, MsgDef};
use super::names::{TIME, UUID};

/// Nav2's planner action, and the parts rosidl generates for it: the goal, result and
/// feedback messages, the feedback message with its goal id, and the two services
/// (`_SendGoal`, `_GetResult`) an action is made of on the wire.
pub const COMPUTE_PATH_TO_POSE: &str = "nav2_msgs/action/ComputePathToPose";
pub const COMPUTE_PATH_GOAL: &str = "nav2_msgs/action/ComputePathToPose_Goal";
pub const COMPUTE_PATH_RESULT: &str = "nav2_msgs/action/ComputePathToPose_Result";
pub const COMPUTE_PATH_FEEDBACK: &str = "nav2_msgs/action/ComputePathToPose_Feedback";
pub const COMPUTE_PATH_FEEDBACK_MESSAGE: &str = COMPUTE_PATH_PARTS[0].name;
pub const COMPUTE_PATH_SEND_GOAL: &str = "nav2_msgs/action/ComputePathToPose_SendGoal";
pub const COMPUTE_PATH_GET_RESULT: &str = "nav2_msgs/action/ComputePathToPose_GetResult";
/// Nav2's controller action (a robot's `follow_path`), and its generated parts.
pub const FOLLOW_PATH_GOAL: &str = "nav2_msgs/action/FollowPath_Goal";
pub const FOLLOW_PATH_RESULT: &str = "nav2_msgs/action/FollowPath_Result";
pub const FOLLOW_PATH_FEEDBACK: &str = "nav2_msgs/action/FollowPath_Feedback";
pub const FOLLOW_PATH_FEEDBACK_MESSAGE: &str = FOLLOW_PATH_PARTS[0].name;
pub const FOLLOW_PATH_SEND_GOAL: &str = "nav2_msgs/action/FollowPath_SendGoal";
pub const FOLLOW_PATH_GET_RESULT: &str = "nav2_msgs/action/FollowPath_GetResult";

/// What rosidl generates for an action besides its goal, result and feedback: the
/// feedback message with its goal id (first), and the request and response of the two
/// services (`_SendGoal`, `_GetResult`) an action is made of on the wire.
macro_rules! action_parts {
    ($action:literal, $goal:expr, $result:expr, $feedback:expr) => {
        [
            MsgDef {
                name: concat!($action, "_FeedbackMessage"),
                fields: &[f("goal_id", Nested(UUID)), f("feedback", Nested($feedback))],
            },
            MsgDef {
                name: concat!($action, "_SendGoal_Request"),
                fields: &[f("goal_id", Nested(UUID)), f("goal", Nested($goal))],
            },
            MsgDef {
                name: concat!($action, "_SendGoal_Response"),
                fields: &[f("accepted", Bool), f("stamp", Nested(TIME))],
            },
            MsgDef {
                name: concat!($action, "_GetResult_Request"),
                fields: &[f("goal_id", Nested(UUID))],
            },
            MsgDef {
                name: concat!($action, "_GetResult_Response"),
                fields: &[f("status", Int8), f("result", Nested($result))],
            },
        ]
    };
}

pub(super) const COMPUTE_PATH_PARTS: [MsgDef; 5] = action_parts!(
    "nav2_msgs/action/ComputePathToPose",
    COMPUTE_PATH_GOAL,
    COMPUTE_PATH_RESULT,
    COMPUTE_PATH_FEEDBACK
);
pub(super) const FOLLOW_PATH_PARTS: [MsgDef; 5] = action_parts!(
    "nav2_msgs/action/FollowPath",
    FOLLOW_PATH_GOAL,
    FOLLOW_PATH_RESULT,
    FOLLOW_PATH_FEEDBACK
);
