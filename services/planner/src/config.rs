//! The planner service's config file (YAML); every field has a default.
//!
//! ```yaml
//! root: roam
//! instance: planner-a          # default: the Zenoh session id
//! max_concurrent_plans: 2      # more are refused at once with `busy`
//! map_history: 4               # map versions kept for requests that name one
//! information_layer: information  # or change_information: plan on the mapper's P(E>0)
//! # What one plan may cost, checked before any work (crate::limits):
//! max_population_cells: 4000000   # population × longest path the budget allows
//! max_plan_cost: 4000000000       # population × generations × that path length
//! zenoh: { mode: client, connect: { endpoints: ["tcp/router:7447"] } }
//! ```

use serde::Deserialize;

use crate::limits::PlanLimits;

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
    /// changed since a robot last looked. Scores above 100 count as 100
    /// ([`crate::world::MAX_INFORMATION_SCORE`]).
    pub information_layer: String,
    /// Most genes a plan's population may hold: population × the longest path its
    /// budget allows (Eq. 2, [`crate::limits`]). Refused `limit_exceeded` above it.
    pub max_population_cells: u64,
    /// Most work a plan may ask for: population × max_generations × that path length.
    /// Refused `limit_exceeded` above it.
    pub max_plan_cost: u64,
    pub zenoh: Option<serde_json::Value>,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        let limits = PlanLimits::default();
        PlannerConfig {
            root: roam_proto::keys::DEFAULT_ROOT.to_owned(),
            instance: None,
            max_concurrent_plans: 2,
            map_history: 4,
            information_layer: crate::maps::INFORMATION.to_owned(),
            max_population_cells: limits.max_population_cells,
            max_plan_cost: limits.max_plan_cost,
            zenoh: None,
        }
    }
}

impl PlannerConfig {
    /// The size limits of one plan.
    pub fn limits(&self) -> PlanLimits {
        PlanLimits {
            max_population_cells: self.max_population_cells,
            max_plan_cost: self.max_plan_cost,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_example_parses_to_the_defaults() {
        // The config file is YAML; its JSON subset parses the same way.
        let text = r#"{"max_population_cells": 4000000, "max_plan_cost": 4000000000}"#;
        let parsed: PlannerConfig = serde_json::from_str(text).expect("parses");
        assert_eq!(parsed, PlannerConfig::default());
    }
}
