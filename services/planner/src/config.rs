//! The planner service's config file (YAML); every field has a default.
//!
//! ```yaml
//! root: roam
//! instance: planner-a          # default: the Zenoh session id
//! max_concurrent_plans: 2      # plans computed at once; the next ones queue
//! max_queued_plans: 64         # 1..=10000; a request that cannot make its deadline is refused `busy` at once
//! map_history: 4               # map versions kept for requests that name one
//! information_layer: information  # or change_information: plan on the mapper's P(E>0)
//! change_layer: change_information # optional: plan on max(information, change) (crate::coupling)
//! coupling: max                # or news: interest × the probability of news (crate::coupling::news_product), with change_layer: news
//! news_floor: 0.25             # 0..=1: the share of interest a just-seen cell keeps under coupling: news
//! obstacles_layer: occupied_now # optional: plan around what the fleet saw occupied (crate::seen)
//! obstacle_inflation_m: 0.3    # how far around each such cell, metres (0..=5)
//! planning_resolution_m: 0.2   # optional; default 0.2 (paper 000), or the map's if coarser (crate::resolution)
//! # What one plan may cost, checked before any work (crate::limits):
//! max_population_cells: 4000000   # population × longest path the budget allows
//! max_plan_cost: 4000000000       # population × generations × that path length
//! # The CPU budget across clients, in plan-seconds (crate::budget):
//! max_plan_seconds: 30         # one plan's wall time at most (its deadline is cut)
//! plan_seconds_per_second: 0.5 # the bucket's refill
//! plan_seconds_burst: 60       # the bucket's size
//! zenoh: { mode: client, connect: { endpoints: ["tcp/router:7447"] } }
//! ```

use roam_runtime::service_config::{ServiceConfig, UnknownFields};
use serde::Deserialize;

use crate::budget::BudgetConfig;
use crate::coupling::Coupling;
use crate::limits::PlanLimits;

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct PlannerConfig {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    /// Plans computed at once by this instance; the next requests wait in its queue
    /// ([`crate::queue`]).
    pub max_concurrent_plans: usize,
    /// Requests the queue holds at most (1..=[`crate::queue::MAX_QUEUED_PLANS`]); a
    /// request is admitted when its expected wait plus planning fits its deadline, and
    /// refused `busy` at once otherwise, with the expected wait.
    pub max_queued_plans: usize,
    /// How many map versions to keep for requests that name a `map_version`.
    pub map_history: usize,
    /// The u8 layer the planner takes as paper 000's information map I_xy: the map
    /// server's static `information` (default), or the mapper's `change_information`
    /// (100 · P(E > 0), paper 004), so curiosity goes where the world has likely
    /// changed since a robot last looked. Scores above 100 count as 100
    /// ([`crate::world::MAX_INFORMATION_SCORE`]).
    pub information_layer: String,
    /// A u8 change layer (the mapper's `change_information`) coupled into the
    /// information map: the planner plans on max(I_xy, C_xy) cell by cell
    /// ([`crate::coupling`]). Off by default.
    pub change_layer: Option<String>,
    /// How the change layer is coupled ([`crate::coupling`]): `max` (default),
    /// max(I_xy, C_xy); or `news`, interest × the probability of news scaled to the
    /// best interest ([`crate::coupling::news_product`]), with the mapper's `news` layer
    /// as `change_layer` (required).
    pub coupling: Coupling,
    /// The news product's floor ε, 0 to 1 ([`crate::coupling`]: why a floor): the share
    /// of its interest a cell keeps however recently a robot saw it. Used by `coupling:
    /// news` only.
    pub news_floor: f64,
    /// An i8 layer of the world now (the mapper's `occupied_now`): cells it believes
    /// occupied where the static map is free are planned around ([`crate::seen`]). Off
    /// by default.
    pub obstacles_layer: Option<String>,
    /// How far around each such cell the plan keeps off, metres (the robot's radius and
    /// a margin; at most [`crate::seen::MAX_OBSTACLE_INFLATION_M`]).
    pub obstacle_inflation_m: f64,
    /// The resolution the planner plans at, metres ([`crate::resolution`]): planning
    /// cells of a whole number of map cells, the path driven on the map's cells. Absent:
    /// paper 000's 0.2 m, or the map's resolution where that is coarser. Finer than the
    /// map's, or coarser than [`crate::resolution::MAX_PLANNING_RESOLUTION_M`], is
    /// refused naming `planning_resolution_m`.
    pub planning_resolution_m: Option<f64>,
    /// Most genes a plan's population may hold: population × the longest path its
    /// budget allows (Eq. 2, [`crate::limits`]). Refused `limit_exceeded` above it.
    pub max_population_cells: u64,
    /// Most work a plan may ask for: population × max_generations × that path length.
    /// Refused `limit_exceeded` above it.
    pub max_plan_cost: u64,
    /// One plan's wall time at most, seconds: a longer `deadline_s` is cut to it and a
    /// plan that runs into it replies `stop_reason: cpu_grant` ([`crate::budget`]).
    pub max_plan_seconds: f64,
    /// Plan-seconds the instance's CPU budget refills per wall second.
    pub plan_seconds_per_second: f64,
    /// Plan-seconds the CPU budget holds at most.
    pub plan_seconds_burst: f64,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        let limits = PlanLimits::default();
        let budget = BudgetConfig::default();
        PlannerConfig {
            service: ServiceConfig::default(),
            max_concurrent_plans: 2,
            max_queued_plans: 64,
            map_history: 4,
            information_layer: crate::maps::INFORMATION.to_owned(),
            change_layer: None,
            coupling: Coupling::Max,
            news_floor: crate::coupling::DEFAULT_NEWS_FLOOR,
            obstacles_layer: None,
            obstacle_inflation_m: 0.3,
            planning_resolution_m: None,
            max_population_cells: limits.max_population_cells,
            max_plan_cost: limits.max_plan_cost,
            max_plan_seconds: budget.max_plan_seconds,
            plan_seconds_per_second: budget.plan_seconds_per_second,
            plan_seconds_burst: budget.plan_seconds_burst,
            unknown: UnknownFields,
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

    /// The CPU budget's numbers.
    pub fn budget(&self) -> BudgetConfig {
        BudgetConfig {
            max_plan_seconds: self.max_plan_seconds,
            plan_seconds_per_second: self.plan_seconds_per_second,
            plan_seconds_burst: self.plan_seconds_burst,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_example_parses_to_the_defaults() {
        // The config file is YAML; its JSON subset parses the same way.
        let text = r#"{"max_population_cells": 4000000, "max_plan_cost": 4000000000,
            "max_plan_seconds": 30, "plan_seconds_per_second": 0.5, "plan_seconds_burst": 60}"#;
        let parsed: PlannerConfig = serde_json::from_str(text).expect("parses");
        assert_eq!(parsed, PlannerConfig::default());
        assert!(parsed.budget().validate().is_ok());
        // Well under the 600 s a request may ask for.
        assert!(parsed.max_plan_seconds <= 60.0);
    }

    #[test]
    fn the_coupling_is_max_unless_news_is_named() {
        assert_eq!(PlannerConfig::default().coupling, Coupling::Max);
        let news: PlannerConfig =
            serde_json::from_str(r#"{"change_layer": "news", "coupling": "news"}"#).expect("news");
        assert_eq!(news.coupling, Coupling::News);
        assert_eq!(news.news_floor, crate::coupling::DEFAULT_NEWS_FLOOR);
        let floorless: PlannerConfig =
            serde_json::from_str(r#"{"coupling": "news", "news_floor": 0}"#).expect("floor 0");
        assert_eq!(floorless.news_floor, 0.0);
        assert!(serde_json::from_str::<PlannerConfig>(r#"{"coupling": "sum"}"#).is_err());
    }
}
