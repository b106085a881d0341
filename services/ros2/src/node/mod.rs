//! The Zenoh adapter: the `roam ros2` role. One rmw_zenoh node (`/roam` by default) that
//! publishes roam's maps, plans, estimates and driven paths as ROS 2 topics (and the
//! robots' frames on `/tf`), serves the planner as two ROS 2 services and Nav2's
//! `ComputePathToPose` action, optionally takes its occupancy map from a ROS 2
//! publisher, and optionally records everything it publishes as a rosbag2.
//!
//! It talks to roam's services through roam's own keys, as any client would, and to
//! ROS 2 through rmw_zenoh's keys, tokens and attachments ([`crate::wire`]). Nothing
//! from either side is trusted: payloads are capped before they are read, names are
//! checked, and each refusal is logged, rate-limited, naming the limit.

mod action_client;
mod compute_path;
mod follow;
mod map_input;
mod nav2_robot;
mod output;
mod poses;
mod services;
mod sim_time;

use std::path::PathBuf;
use std::sync::Arc;

use roam_runtime::{Service, ServiceError};
use tokio_util::sync::CancellationToken;

use crate::names::{self, NodeInfo};

pub use compute_path::{
    DEFAULT_ACTION as COMPUTE_PATH_ACTION, MAX_GOALS, MAX_RUNNING_GOALS, PLANNER_IDS,
};
pub use nav2_robot::{Nav2Robot, MAX_NAV2_ROBOTS};
pub use output::Output;
/// What every call to the node's services is promised (see `services`).
pub use services::{
    GET_PLAN, GET_PLAN_ANSWER_S, MAX_CONCURRENT_CALLS, MAX_REQUEST_BYTES, PLAN_DOWNTIME,
};

/// The role's name in `<root>/@live/ros2/<instance>`.
pub const SERVICE_NAME: &str = "ros2";

/// What `roam ros2` does (its config file, `roam ros2 --config`, as every role's).
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Ros2Config {
    /// roam's key root.
    pub root: String,
    /// roam's instance name (default: the Zenoh session id).
    pub instance: Option<String>,
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
    /// A Zenoh config fragment, lowest precedence (see `roam_runtime::session`).
    pub zenoh: Option<serde_json::Value>,
}

impl Default for Ros2Config {
    fn default() -> Self {
        Ros2Config {
            root: roam_proto::keys::DEFAULT_ROOT.to_owned(),
            instance: None,
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
            zenoh: None,
        }
    }
}

/// The map server's default `max_layer_cells` (4096²).
pub const MAX_LAYER_CELLS: u64 = 16_777_216;

/// The largest ROS domain id (ROS 2 allows 0 to 232).
pub const MAX_DOMAIN_ID: u32 = 232;

#[derive(Debug, thiserror::Error)]
pub enum Ros2Error {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Name(#[from] names::NameError),
    #[error("ROS_DOMAIN_ID {0} is out of range: ROS 2 uses 0 to {MAX_DOMAIN_ID}")]
    Domain(u32),
    #[error("roam ros2 has nothing to do: it neither offers topics to ROS 2 nor records")]
    NothingToDo,
    #[error("{0} Nav2 robots; one node drives at most {MAX_NAV2_ROBOTS}")]
    TooManyRobots(usize),
    #[error(transparent)]
    Bag(#[from] crate::bag::BagError),
    #[error("cannot declare {what} on '{key}': {reason}")]
    Declare {
        what: &'static str,
        key: String,
        reason: String,
    },
}

/// Runs the role until `cancel`; the liveliness token `<root>/@live/ros2/<instance>`
/// appears once every topic, service and subscription is declared.
pub async fn run(
    config: Ros2Config,
    zenoh: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), Ros2Error> {
    if config.domain > MAX_DOMAIN_ID {
        return Err(Ros2Error::Domain(config.domain));
    }
    names::check_namespace(&config.namespace)?;
    names::check_node_name(&config.node_name)?;
    if !config.offer && config.rosbag.is_none() {
        return Err(Ros2Error::NothingToDo);
    }
    if config.nav2_robots.len() > MAX_NAV2_ROBOTS {
        return Err(Ros2Error::TooManyRobots(config.nav2_robots.len()));
    }
    let bag = config
        .rosbag
        .as_deref()
        .map(crate::bag::Bag::create)
        .transpose()?;
    let mut service = Service::start(
        SERVICE_NAME,
        &config.root,
        config.instance.as_deref(),
        zenoh,
        cancel,
    )
    .await?;
    let session = service.session().clone();
    let node = NodeInfo {
        domain: config.domain,
        session: session.zid().to_string(),
        node_id: 0,
        namespace: config.namespace.clone(),
        name: config.node_name.clone(),
        enclave: String::new(),
    };
    let taken = match &config.map_input {
        Some(topic) => Some(names::qualify(&config.namespace, topic)?),
        None => None,
    };
    let output = Arc::new(Output::new(
        session.clone(),
        node.clone(),
        config.offer,
        bag,
        taken,
    ));
    let node_token = if config.offer {
        Some(output.declare_node().await?)
    } else {
        None
    };
    let subscriptions = roam_runtime::FleetStreams::declare(&session, &config.root).await?;
    let poses = Arc::new(poses::RobotPoses::default());
    if config.offer {
        services::declare(&service, output.clone(), &config.root).await?;
        if let Some(action) = &config.compute_path_action {
            compute_path::declare(
                &service,
                output.clone(),
                &config.root,
                action,
                config.robot.clone(),
                poses.clone(),
            )
            .await?;
        }
    }
    if let Some(topic) = &config.map_input {
        map_input::declare(&service, output.clone(), &config, topic).await?;
    }
    let mission_clock = match &config.clock {
        Some(topic) => sim_time::declare(&service, output.clone(), &config.root, topic).await?,
        None => sim_time::MissionClock::default(),
    };
    for robot in &config.nav2_robots {
        nav2_robot::declare(
            &service,
            output.clone(),
            &config.root,
            robot.clone(),
            mission_clock.clone(),
        )
        .await?;
    }
    let (root, out, stop) = (config.root.clone(), output.clone(), service.cancel_token());
    service.spawn(follow::run(
        session.clone(),
        root,
        subscriptions,
        out,
        poses,
        stop,
    ));
    service.announce().await?;
    if config.offer {
        tracing::info!(
            domain = config.domain,
            node = %format!("{}{}{}", config.namespace, if config.namespace == "/" { "" } else { "/" }, config.node_name),
            "roam ros2: node up on rmw_zenoh's keys"
        );
    }
    service.cancelled().await;
    let outcome = service.shutdown(roam_runtime::service::DEFAULT_GRACE).await;
    drop(node_token);
    if let Some(summary) = output.finish_bag()? {
        tracing::info!(
            dir = %summary.dir.display(),
            messages = summary.messages,
            "roam ros2: rosbag2 recording complete"
        );
    }
    outcome.map_err(Ros2Error::from)
}
