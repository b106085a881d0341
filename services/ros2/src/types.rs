//! The ROS 2 interface definitions roam speaks, as data: every field of every message
//! and service in order, with its type as REP-2011's type description numbers it.
//!
//! One table serves three readers: the RIHS01 type hashes ([`crate::hash`]), the
//! `ros2msg` schemas of a rosbag2 recording ([`message_definition`]), and the tests that
//! hold the serde structs of [`crate::msg`] to the same field order. The definitions are
//! those of ROS 2 Jazzy's `builtin_interfaces`, `std_msgs`, `geometry_msgs`, `nav_msgs`
//! and `service_msgs`, less their comments, constants and default values (none of which
//! are hashed), and roam's own `roam_interfaces/srv/PlanDowntime` (its `.srv` file ships
//! in `services/ros2/roam_interfaces/srv/`; a test checks the two agree).

/// A field's element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Base {
    Int8,
    Uint8,
    Uint16,
    Int32,
    Uint32,
    Int64,
    Uint64,
    Float32,
    Float64,
    Bool,
    String,
    /// A `char` in a `.msg` file: rosidl maps it to an 8-bit unsigned integer.
    Char,
    /// Another message, by its full name (`geometry_msgs/msg/Pose`).
    Nested(&'static str),
}

/// Single, fixed array, bounded or unbounded sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    Single,
    Array(u32),
    Bounded(u32),
    Unbounded,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub base: Base,
    pub shape: Shape,
}

/// A message: its full name (`pkg/msg/Name`, or `pkg/srv/Name_Request` for a service's
/// parts) and its fields in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MsgDef {
    pub name: &'static str,
    pub fields: &'static [Field],
}

const fn f(name: &'static str, base: Base) -> Field {
    Field {
        name,
        base,
        shape: Shape::Single,
    }
}

const fn shaped(name: &'static str, base: Base, shape: Shape) -> Field {
    Field { name, base, shape }
}

use Base::{
    Bool, Char, Float32, Float64, Int32, Int64, Int8, Nested, Uint16, Uint32, Uint64, Uint8,
};

pub const TIME: &str = "builtin_interfaces/msg/Time";
pub const HEADER: &str = "std_msgs/msg/Header";
pub const POINT: &str = "geometry_msgs/msg/Point";
pub const QUATERNION: &str = "geometry_msgs/msg/Quaternion";
pub const POSE: &str = "geometry_msgs/msg/Pose";
pub const POSE_STAMPED: &str = "geometry_msgs/msg/PoseStamped";
pub const POSE_WITH_COVARIANCE: &str = "geometry_msgs/msg/PoseWithCovariance";
pub const POSE_WITH_COVARIANCE_STAMPED: &str = "geometry_msgs/msg/PoseWithCovarianceStamped";
pub const MAP_META_DATA: &str = "nav_msgs/msg/MapMetaData";
pub const OCCUPANCY_GRID: &str = "nav_msgs/msg/OccupancyGrid";
pub const PATH: &str = "nav_msgs/msg/Path";
pub const SERVICE_EVENT_INFO: &str = "service_msgs/msg/ServiceEventInfo";
pub const GET_PLAN: &str = "nav_msgs/srv/GetPlan";
pub const PLAN_DOWNTIME: &str = "roam_interfaces/srv/PlanDowntime";
pub const DURATION: &str = "builtin_interfaces/msg/Duration";
pub const UUID: &str = "unique_identifier_msgs/msg/UUID";
pub const GOAL_INFO: &str = "action_msgs/msg/GoalInfo";
pub const GOAL_STATUS: &str = "action_msgs/msg/GoalStatus";
pub const GOAL_STATUS_ARRAY: &str = "action_msgs/msg/GoalStatusArray";
pub const CANCEL_GOAL: &str = "action_msgs/srv/CancelGoal";
pub const VECTOR3: &str = "geometry_msgs/msg/Vector3";
pub const TRANSFORM: &str = "geometry_msgs/msg/Transform";
pub const TRANSFORM_STAMPED: &str = "geometry_msgs/msg/TransformStamped";
pub const TF_MESSAGE: &str = "tf2_msgs/msg/TFMessage";
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
pub const CLOCK: &str = "rosgraph_msgs/msg/Clock";
pub const EMPTY: &str = "std_msgs/msg/Empty";
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

const COMPUTE_PATH_PARTS: [MsgDef; 5] = action_parts!(
    "nav2_msgs/action/ComputePathToPose",
    COMPUTE_PATH_GOAL,
    COMPUTE_PATH_RESULT,
    COMPUTE_PATH_FEEDBACK
);
const FOLLOW_PATH_PARTS: [MsgDef; 5] = action_parts!(
    "nav2_msgs/action/FollowPath",
    FOLLOW_PATH_GOAL,
    FOLLOW_PATH_RESULT,
    FOLLOW_PATH_FEEDBACK
);

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

/// `pkg/msg/Name` as DDS names it, which is what rmw_zenoh puts in its keys:
/// `pkg::msg::dds_::Name_`. A service (`pkg/srv/Name`) becomes `pkg::srv::dds_::Name_`.
pub fn dds_type_name(name: &str) -> Option<String> {
    let mut parts = name.split('/');
    let (Some(package), Some(kind), Some(short), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return None;
    };
    Some(format!("{package}::{kind}::dds_::{short}_"))
}

/// How a `.msg` file names a field's type: `int8`, `geometry_msgs/Pose`, with `[36]`,
/// `[<=1]` or `[]` for arrays and sequences.
fn msg_type_text(field: &Field) -> String {
    let base = match field.base {
        Int8 => "int8".to_owned(),
        Uint8 => "uint8".to_owned(),
        Uint16 => "uint16".to_owned(),
        Int32 => "int32".to_owned(),
        Uint32 => "uint32".to_owned(),
        Int64 => "int64".to_owned(),
        Uint64 => "uint64".to_owned(),
        Float32 => "float32".to_owned(),
        Float64 => "float64".to_owned(),
        Bool => "bool".to_owned(),
        Base::String => "string".to_owned(),
        Char => "char".to_owned(),
        Nested(name) => short_name(name),
    };
    match field.shape {
        Shape::Single => base,
        Shape::Array(n) => format!("{base}[{n}]"),
        Shape::Bounded(n) => format!("{base}[<={n}]"),
        Shape::Unbounded => format!("{base}[]"),
    }
}

/// `geometry_msgs/msg/Pose` as `.msg` files and rosbag2 schemas write it:
/// `geometry_msgs/Pose`.
fn short_name(name: &str) -> String {
    match name.split('/').collect::<Vec<_>>().as_slice() {
        [package, _, short] => format!("{package}/{short}"),
        _ => name.to_owned(),
    }
}

/// The `.msg` text of one message (its fields, one a line).
pub fn msg_text(def: &MsgDef) -> String {
    def.fields
        .iter()
        .map(|field| format!("{} {}\n", msg_type_text(field), field.name))
        .collect()
}

/// Every message `name` refers to, directly or not, sorted by name and without `name`.
pub fn dependencies(name: &str) -> Vec<&'static MsgDef> {
    let mut found: Vec<&'static MsgDef> = Vec::new();
    let mut todo = vec![name.to_owned()];
    while let Some(next) = todo.pop() {
        let Some(def) = message(&next) else { continue };
        for field in def.fields {
            if let Nested(nested) = field.base {
                if nested != name && !found.iter().any(|d| d.name == nested) {
                    if let Some(dep) = message(nested) {
                        found.push(dep);
                        todo.push(nested.to_owned());
                    }
                }
            }
        }
    }
    found.sort_by_key(|d| d.name);
    found
}

/// The `ros2msg` schema rosbag2 stores for a topic of type `name`: the message's own
/// text, then each dependency after a line of 80 `=` and `MSG: pkg/Name` (the layout of
/// rosbag2's `LocalMessageDefinitionSource`, which every rosbag2 reader parses).
pub fn message_definition(name: &str) -> Option<String> {
    let def = message(name)?;
    let mut text = msg_text(def);
    for dep in dependencies(name) {
        text.push_str(&"=".repeat(80));
        text.push('\n');
        text.push_str(&format!("MSG: {}\n", short_name(dep.name)));
        text.push_str(&msg_text(dep));
    }
    Some(text)
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

    #[test]
    fn dds_names_are_rmw_zenoh_s() {
        assert_eq!(
            dds_type_name(OCCUPANCY_GRID).as_deref(),
            Some("nav_msgs::msg::dds_::OccupancyGrid_")
        );
        assert_eq!(
            dds_type_name(GET_PLAN).as_deref(),
            Some("nav_msgs::srv::dds_::GetPlan_")
        );
        assert_eq!(dds_type_name("nav_msgs/OccupancyGrid"), None);
    }

    #[test]
    fn a_schema_lists_the_message_then_its_dependencies_sorted() {
        let text = message_definition(PATH).expect("Path");
        assert!(text.starts_with("std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n"));
        let order: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("MSG: "))
            .collect();
        assert_eq!(
            order,
            [
                "builtin_interfaces/Time",
                "geometry_msgs/Point",
                "geometry_msgs/Pose",
                "geometry_msgs/PoseStamped",
                "geometry_msgs/Quaternion",
                "std_msgs/Header"
            ]
        );
    }

    /// The `.srv` file shipped for colcon says what this table says.
    #[test]
    fn the_shipped_srv_file_matches_the_table() {
        let srv = include_str!("../roam_interfaces/srv/PlanDowntime.srv");
        let fields = |text: &str| -> Vec<String> {
            text.lines()
                .map(|l| l.split('#').next().unwrap_or("").trim())
                .filter(|l| !l.is_empty())
                .map(|l| l.split_whitespace().take(2).collect::<Vec<_>>().join(" "))
                .collect()
        };
        let (request, response) = srv.split_once("\n---\n").expect("a --- line");
        let want = |name: &str| -> Vec<String> {
            let def = message(name).expect("defined");
            fields(&msg_text(def))
        };
        assert_eq!(
            fields(request),
            want("roam_interfaces/srv/PlanDowntime_Request")
        );
        assert_eq!(
            fields(response),
            want("roam_interfaces/srv/PlanDowntime_Response")
        );
    }
}
