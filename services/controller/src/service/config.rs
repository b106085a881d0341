//! The controller service's config file and the errors that stop it from starting.

use std::path::PathBuf;

use roam_runtime::service_config::{ServiceConfig, UnknownFields};
use roam_runtime::ServiceError;
use serde::Deserialize;

use crate::params::ApfParams;

/// The controller service's config file (YAML).
///
/// ```yaml
/// root: roam
/// scenario: config/scenarios/es1.yaml   # obstacles, anchors, sensing; default: built-in world
/// stale_after_s: 1.0                    # zero command when estimates stop this long
/// release_after_s: 30.0                 # forget a robot whose estimates stopped this long
/// robots: [r1]                          # drive only these robots; default: every robot
/// apf:                                  # paper 002 §4's values are the defaults
///   scheme: linear                      # plain | fixed | cutoff | linear | sinusoidal
///   z_is: 0.8
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct ControllerConfig {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    pub scenario: Option<PathBuf>,
    pub stale_after_s: f64,
    /// A robot whose estimates have stopped this long (wall time; at least twice
    /// `stale_after_s`) is gone: its slot is released. A mission for a robot without an
    /// estimate this recent waits (at most
    /// [`MAX_HELD_MISSIONS`](crate::service::MAX_HELD_MISSIONS) of them, each this long)
    /// for the robot's first estimate, so missions for robots that do not exist never
    /// take a slot.
    pub release_after_s: f64,
    /// The robots this instance drives; empty: every robot that is given a mission. A
    /// controller on board a robot names its own, so it subscribes only to that robot's
    /// missions and estimates (nothing else crosses the robot's link) and never drives
    /// another robot when a fleet runs one controller per robot.
    pub robots: Vec<String>,
    pub apf: ApfParams,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig {
            service: ServiceConfig::default(),
            scenario: None,
            stale_after_s: 1.0,
            release_after_s: 30.0,
            robots: Vec::new(),
            apf: ApfParams::default(),
            unknown: UnknownFields,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ControllerServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Scenario(#[from] roam_world::scenario::ScenarioError),
    #[error("invalid config: {0}")]
    Config(String),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_config_is_the_indoor_controller() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/controller.yaml");
        let config: ControllerConfig = roam_runtime::config_file::load(&path).expect("parses");
        assert_eq!(config.apf, ApfParams::indoor());
        assert!(
            config.robots.is_empty(),
            "the shipped controller drives any robot"
        );
    }
}
