//! The mapper's config file and the errors that stop it from starting.

use std::path::PathBuf;

use roam_runtime::service_config::{ServiceConfig, UnknownFields};
use roam_runtime::ServiceError;
use serde::Deserialize;

use crate::belief::BeliefParams;
use crate::change_map::MapParams;
use crate::explorer::ExplorerParams;
use crate::news::NewsParams;

/// The mapper's config file (YAML).
///
/// ```yaml
/// root: roam
/// scenario: config/scenarios/grid004.yaml   # the map the layers cover; default: built-in world
/// explore: [robot]                          # robots the curious learner drives (default none)
/// publish_period_s: 1.0                     # the layers go to the map server at most this often
/// seed: 0
/// news:                                     # the news value (crate::news)
///   prior: { alpha: 1.0, beta_s: 3600.0 }  # λ̂ = (c + α)/(S + β), news.rs
///   reserve: { s_per_m: 2.0 }               # radius_m: default the scenario's observation radius
/// belief:                                   # the map now (crate::belief)
///   prior: { alpha: 0.0001, beta_s: 60.0 }
///   unseen_occupied: 0.5                    # a cell never seen where the static map has no value
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct MapperConfig {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    pub scenario: Option<PathBuf>,
    pub explore: Vec<String>,
    pub publish_period_s: f64,
    pub seed: u64,
    pub explorer: ExplorerParams,
    /// The map's parameters; `observation_period_s` is taken from the scenario's step.
    pub map: MapParams,
    /// The news value's prior and how missions become reservations.
    pub news: NewsParams,
    /// The map now's prior.
    pub belief: BeliefParams,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for MapperConfig {
    fn default() -> Self {
        MapperConfig {
            service: ServiceConfig::default(),
            scenario: None,
            explore: Vec::new(),
            publish_period_s: 1.0,
            seed: 0,
            explorer: ExplorerParams::default(),
            map: MapParams::default(),
            news: NewsParams::default(),
            belief: BeliefParams::default(),
            unknown: UnknownFields,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum MapperServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Scenario(#[from] roam_world::scenario::ScenarioError),
    #[error("invalid config: {0}")]
    Config(String),
}
