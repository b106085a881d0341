//! `roam ros2`: roam in a ROS 2 system over rmw_zenoh (`roam_ros2::node`); and the flags
//! that add the same node to `roam stack` and `roam demo`. See services/ros2/README.md.

use std::path::PathBuf;

use clap::Args;
use roam_ros2::node::Ros2Config;
use roam_stack::Role;

use super::service_args::ServiceArgs;

/// The ROS 2 side of the node: shared by `roam ros2`, `roam stack` and `roam demo`.
#[derive(Debug, Args, Clone)]
pub(crate) struct RosFlags {
    /// The ROS 2 domain (ROS_DOMAIN_ID), the first segment of every ROS 2 key; default 0.
    #[arg(long = "ros-domain-id", env = "ROS_DOMAIN_ID")]
    domain: Option<u32>,
    /// The node's namespace, `/` or `/site1` (relative topics such as `map` live in it);
    /// default `/`.
    #[arg(long = "ros-namespace")]
    namespace: Option<String>,
    /// The ROS 2 node's name; default `roam`.
    #[arg(long = "ros-node-name")]
    node_name: Option<String>,
    /// Take the map server's occupancy from this ROS 2 topic of nav_msgs/msg/OccupancyGrid
    /// (e.g. `/map` from Nav2's map_server): a new occupancy version per map received.
    #[arg(long = "ros2-map", value_name = "TOPIC")]
    ros2_map: Option<String>,
}

impl RosFlags {
    /// The ROS 2 node's config from these flags alone (`roam stack --ros2`, `roam demo
    /// --ros2`).
    pub(crate) fn config(&self) -> Ros2Config {
        let mut config = Ros2Config::default();
        self.apply(&mut config);
        config
    }

    /// The flags given over a config (from `roam ros2 --config`, or the defaults): a
    /// flag left out keeps the config's value.
    pub(crate) fn apply(&self, config: &mut Ros2Config) {
        if let Some(domain) = self.domain {
            config.domain = domain;
        }
        if let Some(namespace) = &self.namespace {
            config.namespace = namespace.clone();
        }
        if let Some(node_name) = &self.node_name {
            config.node_name = node_name.clone();
        }
        if self.ros2_map.is_some() {
            config.map_input = self.ros2_map.clone();
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
    let mut config: Ros2Config = args.service.load_config()?;
    args.ros.apply(&mut config);
    if args.rosbag.is_some() {
        config.rosbag = args.rosbag;
    }
    args.service.run(Role::from(config)).await
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Debug, Parser)]
    struct Flags {
        #[command(flatten)]
        ros: RosFlags,
    }

    #[test]
    fn flags_left_out_keep_the_config_files_values() {
        let flags = Flags::try_parse_from(["roam", "--ros-node-name", "site"]).expect("flags");
        let mut config: Ros2Config =
            serde_json::from_str(r#"{"domain": 5, "namespace": "/a", "map_input": "/map"}"#)
                .expect("config");
        flags.ros.apply(&mut config);
        assert_eq!(config.node_name, "site", "a flag given wins");
        if std::env::var_os("ROS_DOMAIN_ID").is_none() {
            assert_eq!(config.domain, 5, "a flag left out keeps the file's value");
        }
        assert_eq!(config.namespace, "/a");
        assert_eq!(config.map_input.as_deref(), Some("/map"));
        let defaults = Flags::try_parse_from(["roam"]).expect("flags").ros.config();
        assert_eq!(defaults.namespace, "/");
        assert_eq!(defaults.node_name, "roam");
    }
}
