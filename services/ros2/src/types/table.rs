//! The table: every message and service written out, field by field, in order.

use super::actions::*;
use super::def::Base::{
    Bool, Char, Float32, Float64, Int32, Int64, Int8, Nested, Uint16, Uint32, Uint64, Uint8,
};
use super::def::{f, shaped, Base, MsgDef, Shape};
use super::names::*;

/// Every message definition, dependencies included: [`MESSAGES`] and the actions' parts.
pub fn all_messages() -> impl Iterator<Item = &'static MsgDef> {
    MESSAGES
        .iter()
        .chain(COMPUTE_PATH_PARTS.iter())
        .chain(FOLLOW_PATH_PARTS.iter())
}

/// The message definitions written out (the actions' generated parts are in
/// [`all_messages`]).
pub const MESSAGES: &[MsgDef] = &[
    MsgDef {
        name: TIME,
        fields: &[f("sec", Int32), f("nanosec", Uint32)],
    },
    MsgDef {
        name: HEADER,
        fields: &[f("stamp", Nested(TIME)), f("frame_id", Base::String)],
    },
    MsgDef {
        name: POINT,
        fields: &[f("x", Float64), f("y", Float64), f("z", Float64)],
    },
    MsgDef {
        name: QUATERNION,
        fields: &[
            f("x", Float64),
            f("y", Float64),
            f("z", Float64),
            f("w", Float64),
        ],
    },
    MsgDef {
        name: POSE,
        fields: &[
            f("position", Nested(POINT)),
            f("orientation", Nested(QUATERNION)),
        ],
    },
    MsgDef {
        name: POSE_STAMPED,
        fields: &[f("header", Nested(HEADER)), f("pose", Nested(POSE))],
    },
    MsgDef {
        name: POSE_WITH_COVARIANCE,
        fields: &[
            f("pose", Nested(POSE)),
            shaped("covariance", Float64, Shape::Array(36)),
        ],
    },
    MsgDef {
        name: POSE_WITH_COVARIANCE_STAMPED,
        fields: &[
            f("header", Nested(HEADER)),
            f("pose", Nested(POSE_WITH_COVARIANCE)),
        ],
    },
    MsgDef {
        name: MAP_META_DATA,
        fields: &[
            f("map_load_time", Nested(TIME)),
            f("resolution", Float32),
            f("width", Uint32),
            f("height", Uint32),
            f("origin", Nested(POSE)),
        ],
    },
    MsgDef {
        name: OCCUPANCY_GRID,
        fields: &[
            f("header", Nested(HEADER)),
            f("info", Nested(MAP_META_DATA)),
            shaped("data", Int8, Shape::Unbounded),
        ],
    },
    MsgDef {
        name: PATH,
        fields: &[
            f("header", Nested(HEADER)),
            shaped("poses", Nested(POSE_STAMPED), Shape::Unbounded),
        ],
    },
    MsgDef {
        name: DURATION,
        fields: &[f("sec", Int32), f("nanosec", Uint32)],
    },
    MsgDef {
        name: UUID,
        fields: &[shaped("uuid", Uint8, Shape::Array(16))],
    },
    MsgDef {
        name: GOAL_INFO,
        fields: &[f("goal_id", Nested(UUID)), f("stamp", Nested(TIME))],
    },
    MsgDef {
        name: GOAL_STATUS,
        fields: &[f("goal_info", Nested(GOAL_INFO)), f("status", Int8)],
    },
    MsgDef {
        name: GOAL_STATUS_ARRAY,
        fields: &[shaped("status_list", Nested(GOAL_STATUS), Shape::Unbounded)],
    },
    MsgDef {
        name: "action_msgs/srv/CancelGoal_Request",
        fields: &[f("goal_info", Nested(GOAL_INFO))],
    },
    MsgDef {
        name: "action_msgs/srv/CancelGoal_Response",
        fields: &[
            f("return_code", Int8),
            shaped("goals_canceling", Nested(GOAL_INFO), Shape::Unbounded),
        ],
    },
    MsgDef {
        name: VECTOR3,
        fields: &[f("x", Float64), f("y", Float64), f("z", Float64)],
    },
    MsgDef {
        name: TRANSFORM,
        fields: &[
            f("translation", Nested(VECTOR3)),
            f("rotation", Nested(QUATERNION)),
        ],
    },
    MsgDef {
        name: TRANSFORM_STAMPED,
        fields: &[
            f("header", Nested(HEADER)),
            f("child_frame_id", Base::String),
            f("transform", Nested(TRANSFORM)),
        ],
    },
    MsgDef {
        name: TF_MESSAGE,
        fields: &[shaped(
            "transforms",
            Nested(TRANSFORM_STAMPED),
            Shape::Unbounded,
        )],
    },
    // nav2_msgs/action/ComputePathToPose (Jazzy), less its error-code constants.
    MsgDef {
        name: COMPUTE_PATH_GOAL,
        fields: &[
            f("goal", Nested(POSE_STAMPED)),
            f("start", Nested(POSE_STAMPED)),
            f("planner_id", Base::String),
            f("use_start", Bool),
        ],
    },
    MsgDef {
        name: COMPUTE_PATH_RESULT,
        fields: &[
            f("path", Nested(PATH)),
            f("planning_time", Nested(DURATION)),
            f("error_code", Uint16),
            f("error_msg", Base::String),
        ],
    },
    // An empty feedback: rosidl gives every empty structure this one member, and the
    // type description (so the hash) and the CDR both carry it.
    MsgDef {
        name: COMPUTE_PATH_FEEDBACK,
        fields: &[f("structure_needs_at_least_one_member", Uint8)],
    },
    MsgDef {
        name: CLOCK,
        fields: &[f("clock", Nested(TIME))],
    },
    MsgDef {
        name: EMPTY,
        fields: &[f("structure_needs_at_least_one_member", Uint8)],
    },
    // nav2_msgs/action/FollowPath (Jazzy), less its error-code constants.
    MsgDef {
        name: FOLLOW_PATH_GOAL,
        fields: &[
            f("path", Nested(PATH)),
            f("controller_id", Base::String),
            f("goal_checker_id", Base::String),
            f("progress_checker_id", Base::String),
        ],
    },
    MsgDef {
        name: FOLLOW_PATH_RESULT,
        fields: &[
            f("result", Nested(EMPTY)),
            f("error_code", Uint16),
            f("error_msg", Base::String),
        ],
    },
    MsgDef {
        name: FOLLOW_PATH_FEEDBACK,
        fields: &[f("distance_to_goal", Float32), f("speed", Float32)],
    },
    MsgDef {
        name: SERVICE_EVENT_INFO,
        fields: &[
            f("event_type", Uint8),
            f("stamp", Nested(TIME)),
            shaped("client_gid", Char, Shape::Array(16)),
            f("sequence_number", Int64),
        ],
    },
    MsgDef {
        name: "nav_msgs/srv/GetPlan_Request",
        fields: &[
            f("start", Nested(POSE_STAMPED)),
            f("goal", Nested(POSE_STAMPED)),
            f("tolerance", Float32),
        ],
    },
    MsgDef {
        name: "nav_msgs/srv/GetPlan_Response",
        fields: &[f("plan", Nested(PATH))],
    },
    MsgDef {
        name: "roam_interfaces/srv/PlanDowntime_Request",
        fields: &[
            f("start", Nested(POSE_STAMPED)),
            f("goal", Nested(POSE_STAMPED)),
            f("budget_s", Float64),
            f("model", Base::String),
            f("seed", Uint64),
            f("deadline_s", Float64),
        ],
    },
    MsgDef {
        name: "roam_interfaces/srv/PlanDowntime_Response",
        fields: &[
            f("path", Nested(PATH)),
            f("eta_s", Float64),
            f("information", Float64),
            f("within_budget", Bool),
            f("reaches_goal", Bool),
            f("error_code", Base::String),
            f("error_message", Base::String),
        ],
    },
];

/// The services: their full names; each has `<name>_Request` and `<name>_Response` in
/// [`all_messages`], and rosidl's `<name>_Event` and the service's own description are
/// built from them ([`crate::hash::service_type_hash`]).
pub const SERVICES: &[&str] = &[
    GET_PLAN,
    PLAN_DOWNTIME,
    CANCEL_GOAL,
    COMPUTE_PATH_SEND_GOAL,
    COMPUTE_PATH_GET_RESULT,
    FOLLOW_PATH_SEND_GOAL,
    FOLLOW_PATH_GET_RESULT,
];

/// The definition of message `name`, if roam knows it.
pub fn message(name: &str) -> Option<&'static MsgDef> {
    all_messages().find(|m| m.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_nested_type_is_defined() {
        for def in all_messages() {
            for field in def.fields {
                if let Nested(name) = field.base {
                    assert!(message(name).is_some(), "{} needs {name}", def.name);
                }
            }
        }
        for service in SERVICES {
            assert!(message(&format!("{service}_Request")).is_some());
            assert!(message(&format!("{service}_Response")).is_some());
        }
    }
}
