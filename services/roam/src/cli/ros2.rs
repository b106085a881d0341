//! `roam ros2`: roam in a ROS 2 system over rmw_zenoh (`roam_ros2::node`); and the flags
//! that add the same node to `roam stack` and `roam demo`. See services/ros2/README.md.

use std::path::PathBuf;

use clap::Args;
use roam_ros2::node::Ros2Config;
use roam_runtime::signals;

use super::ServiceArgs;

/// The ROS 2 side of the node: shared by `roam ros2`, `roam stack` and `roam demo`.
#[derive(Debug, Args, Clone)]
pub(crate) struct RosFlags {
    /// The ROS 2 domain (ROS_DOMAIN_ID): the first segment of every ROS 2 key.
    #[arg(long = "ros-domain-id", env = "ROS_DOMAIN_ID", default_value_t = 0)]
    domain: u32,
    /// The node's namespace: `/` or `/site1` (relative topics such as `map` live in it).
    #[arg(long = "ros-namespace", default_value = "/")]
    namespace: String,
    /// The ROS 2 node's name.
    #[arg(long = "ros-node-name", default_value = "roam")]
    node_name: String,
    /// Take the map server's occupancy from this ROS 2 topic of nav_msgs/msg/OccupancyGrid
    /// (e.g. `/map` from Nav2's map_server): a new occupancy version per map received.
    #[arg(long = "ros2-map", value_name = "TOPIC")]
    ros2_map: Option<String>,
}

impl RosFlags {
    pub(crate) fn config(&self) -> Ros2Config {
        Ros2Config {
            domain: self.domain,
            namespace: self.namespace.clone(),
            node_name: self.node_name.clone(),
            map_input: self.ros2_map.clone(),
            ..Ros2Config::default()
        }
    }
}

#[derive(Debug, Args)]
pub(crate) struct Ros2Args {
    #[command(flatten)]
    service: ServiceArgs,
    #[command(flatten)]
    ros: RosFlags,
    /// Also record every message published as a rosbag2 (MCAP) in this new directory.
    #[arg(long, value_name = "DIR")]
    rosbag: Option<PathBuf>,
}

pub(crate) async fn ros2(args: Ros2Args) -> anyhow::Result<()> {
    if args.service.config.is_some() {
        anyhow::bail!("roam ros2 takes no config file: use its flags (roam ros2 --help)");
    }
    let mut config = args.ros.config();
    if let Some(root) = &args.service.root {
        config.root = root.clone();
    }
    config.instance = args.service.instance.clone();
    config.rosbag = args.rosbag;
    let zenoh = args.service.session.zenoh_config(None)?;
    roam_ros2::node::run(config, zenoh, signals::cancel_on_signal()).await?;
    Ok(())
}
