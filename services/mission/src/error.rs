//! What the live executive can fail with, apart from the loop (`executive.rs`) and what
//! it hears (`inputs.rs`), which both report it.

use std::time::Duration;

use roam_runtime::ClientError;

use crate::tasks::TaskError;

/// Why the executive stopped: each names what to fix (the tasks, the config, a layer,
/// the robot's estimates).
#[derive(Debug, thiserror::Error)]
pub enum ExecutiveError {
    #[error(transparent)]
    Tasks(#[from] TaskError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error(transparent)]
    Settings(#[from] crate::config::ConfigError),
    #[error(transparent)]
    Client(#[from] ClientError),
    #[error("the map server's {0} layer is not usable: {1}")]
    Layer(&'static str, String),
    #[error("no estimate of robot {robot:?} within {waited:?}: is localization running and the robot in range of the anchors?")]
    NoEstimate { robot: String, waited: Duration },
    #[error("zenoh: {0}")]
    Zenoh(String),
    #[error("stopped")]
    Cancelled,
}
