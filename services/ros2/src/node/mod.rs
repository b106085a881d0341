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
mod config;
mod error;
mod follow;
mod limits;
mod map_input;
mod nav2_robot;
mod output;
mod poses;
mod services;
mod sim_time;

use std::sync::Arc;

use roam_runtime::Service;
use tokio_util::sync::CancellationToken;

use crate::names::{self, NodeInfo};

pub use compute_path::{
    DEFAULT_ACTION as COMPUTE_PATH_ACTION, MAX_GOALS, MAX_RUNNING_GOALS, PLANNER_IDS,
};
pub use config::{Ros2Config, MAX_LAYER_CELLS};
pub use error::Ros2Error;
pub use limits::{MAX_DOMAIN_ID, MAX_NAV2_ROBOTS};
pub use nav2_robot::Nav2Robot;
pub use output::Output;
/// What every call to the node's services is promised (see `services`).
pub use services::{
    GET_PLAN, GET_PLAN_ANSWER_S, MAX_CONCURRENT_CALLS, MAX_REQUEST_BYTES, PLAN_DOWNTIME,
};

/// The role's name in `<root>/@live/ros2/<instance>`.
pub const SERVICE_NAME: &str = "ros2";

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
    let mut service = Service::start(SERVICE_NAME, &config.service, zenoh, cancel).await?;
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
    let subscriptions = roam_runtime::FleetStreams::declare(&session, &config.service.root).await?;
    let poses = Arc::new(poses::RobotPoses::default());
    if config.offer {
        services::declare(&service, output.clone(), &config.service.root).await?;
        if let Some(action) = &config.compute_path_action {
            compute_path::declare(
                &service,
                output.clone(),
                &config.service.root,
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
        Some(topic) => {
            sim_time::declare(&service, output.clone(), &config.service.root, topic).await?
        }
        None => sim_time::MissionClock::default(),
    };
    for robot in &config.nav2_robots {
        nav2_robot::declare(
            &service,
            output.clone(),
            &config.service.root,
            robot.clone(),
            mission_clock.clone(),
        )
        .await?;
    }
    let (root, out, stop) = (
        config.service.root.clone(),
        output.clone(),
        service.cancel_token(),
    );
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
