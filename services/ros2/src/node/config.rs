//! What `roam ros2` does: the role's config file, and its defaults.

use std::path::PathBuf;

use roam_runtime::service_config::{ServiceConfig, UnknownFields};

use super::compute_path;
use super::nav2_robot::Nav2Robot;

/// What `roam ros2` does (its config file, `roam ros2 --config`, as every role's).
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(default)]
pub struct Ros2Config {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    /// `ROS_DOMAIN_ID`: the first segment of every ROS key.
    pub domain: u32,
    /// The node's namespace (`/` or `/site1`): relative topic names are resolved in it.
    pub namespace: String,
    /// The node's name.
    pub node_name: String,
    /// Declare the node, its topics and services to ROS 2 (off: only record).
    pub offer: bool,
    /// Take the map server's occupancy from this ROS 2 topic (nav_msgs/msg/OccupancyGrid).
    pub map_input: Option<String>,
    /// Serve `nav2_msgs/action/ComputePathToPose` under this name (Nav2's own,
    /// `compute_path_to_pose`, by default; `null`: not served).
    pub compute_path_action: Option<String>,
    /// The robot whose latest estimate starts a ComputePathToPose goal without
    /// `use_start` (default: the only robot localized, if there is one).
    pub robot: Option<String>,
    /// Robots on Nav2 that roam's executive drives: their poses become roam's
    /// estimates, their missions FollowPath goals ([`Nav2Robot`]).
    pub nav2_robots: Vec<Nav2Robot>,
    /// Take roam's mission clock from this ROS 2 topic (rosgraph_msgs/msg/Clock: a
    /// simulator's `/clock`); absent: wall time.
    pub clock: Option<String>,
    /// The map server's `max_layer_cells`: a received map above it is refused.
    pub max_layer_cells: u64,
    /// Record every message published to this new rosbag2 directory.
    pub rosbag: Option<PathBuf>,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for Ros2Config {
    fn default() -> Self {
        Ros2Config {
            service: ServiceConfig::default(),
            domain: 0,
            namespace: "/".to_owned(),
            node_name: "roam".to_owned(),
            offer: true,
            map_input: None,
            compute_path_action: Some(compute_path::DEFAULT_ACTION.to_owned()),
            robot: None,
            nav2_robots: Vec::new(),
            clock: None,
            max_layer_cells: MAX_LAYER_CELLS,
            rosbag: None,
            unknown: UnknownFields,
        }
    }
}

/// The map server's default `max_layer_cells` (4096²).
pub const MAX_LAYER_CELLS: u64 = 16_777_216;
