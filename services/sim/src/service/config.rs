//! The sim service's config file and the errors that stop it from starting.

use std::path::PathBuf;

use roam_runtime::service_config::{ServiceConfig, UnknownFields};
use roam_runtime::ServiceError;
use roam_world::scenario::ScenarioError;
use serde::Deserialize;

use crate::sim::SimError;
use crate::snapshot::SnapshotError;

/// The sim service's config file (YAML).
///
/// ```yaml
/// root: roam
/// scenario: config/scenarios/es1.yaml   # default: the built-in downtime world
/// seed: 0
/// rate: 1.0                             # free-run at 1x; absent: start paused (lock-step)
/// state_file: /var/lib/roam/sim.json    # snapshot here; a restart resumes from it
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct SimConfig {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    pub scenario: Option<PathBuf>,
    pub seed: u64,
    pub rate: Option<f64>,
    /// Where the sim keeps a snapshot of its clock and robots (every
    /// [`SNAPSHOT_PERIOD`](crate::service::SNAPSHOT_PERIOD) while it steps); at start it
    /// resumes from the snapshot when it is of the same scenario and seed. Absent: a
    /// restart begins at step 0.
    pub state_file: Option<PathBuf>,
    /// The directories a control `load` may read scenarios from (names relative to
    /// them; see `roam_world::load_dirs`). Empty: loads from the wire are off.
    pub load_dirs: Vec<PathBuf>,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            service: ServiceConfig::default(),
            scenario: None,
            seed: 0,
            rate: Some(1.0),
            state_file: None,
            load_dirs: Vec::new(),
            unknown: UnknownFields,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SimServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error("the scenario cannot be simulated: {0}")]
    Sim(#[from] SimError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error(transparent)]
    Snapshot(#[from] SnapshotError),
}
