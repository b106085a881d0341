//! The full names of the messages and services roam speaks, and how rmw_zenoh's keys
//! write them (DDS names).

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
pub const CLOCK: &str = "rosgraph_msgs/msg/Clock";
pub const EMPTY: &str = "std_msgs/msg/Empty";

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
