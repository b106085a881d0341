//! Why the `roam ros2` role could not run: a bad config, a name, the rosbag, a declaration.

use roam_runtime::ServiceError;

use super::limits::{MAX_DOMAIN_ID, MAX_NAV2_ROBOTS};
use crate::names;

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
