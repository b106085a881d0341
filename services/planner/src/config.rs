//! The planner service's config file (YAML); every field has a default.
//!
//! ```yaml
//! root: roam
//! instance: planner-a          # default: the Zenoh session id
//! max_concurrent_plans: 2      # more are refused at once with `busy`
//! map_history: 4               # map versions kept for requests that name one
//! information_layer: information  # or change_information: plan on the mapper's P(E>0)
//! zenoh: { mode: client, connect: { endpoints: ["tcp/router:7447"] } }
//! ```

use serde::Deserialize;

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerConfig {
    pub root: String,
    pub instance: Option<String>,
    /// Plans computed at once by this instance; the next request is refused with
    /// `busy` immediately, never queued.
    pub max_concurrent_plans: usize,
    /// How many map versions to keep for requests that name a `map_version`.
    pub map_history: usize,
    /// The u8 layer the planner takes as paper 000's information map I_xy: the map
    /// server's static `information` (default), or the mapper's `change_information`
    /// (100 · P(E > 0), paper 004), so curiosity goes where the world has likely
    /// changed since a robot last looked.
    pub information_layer: String,
    pub zenoh: Option<serde_json::Value>,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        PlannerConfig {
            root: roam_proto::keys::DEFAULT_ROOT.to_owned(),
            instance: None,
            max_concurrent_plans: 2,
            map_history: 4,
            information_layer: crate::maps::INFORMATION.to_owned(),
            zenoh: None,
        }
    }
}
