//! The built-in grid world, the experiment's limits and options, and why it could not
//! run.

use std::path::Path;

use roam_mapper::change_map::{MapParams, MAX_MAP_CELLS};
use roam_mapper::error::MapperError;
use roam_mapper::explorer::ExplorerParams;
use roam_mapper::learner::Mode;
use roam_sim::SimError;
use roam_world::scenario::{self, Scenario};
use serde::Serialize;

use crate::reproduce::mapper::truth::TruthError;

/// The shipped grid world, built in.
pub const GRID004_NAME: &str = "grid004.yaml";
pub const GRID004: &str = include_str!("../../../../../../config/scenarios/grid004.yaml");

/// The most steps per run (limit `max_steps`).
pub const MAX_STEPS: u64 = 10_000_000;
/// The most repetitions per mode (limit `max_repetitions`).
pub const MAX_REPETITIONS: usize = 1000;
/// The most samples per curve (limit `max_samples`).
pub const MAX_SAMPLES: u64 = 100_000;
/// The most worker threads (limit `max_threads`).
pub const MAX_THREADS: usize = 256;

/// Default steps per run: long enough for every strategy's error curve to level off
/// on grid004 (see the crate doc for the figures), and the full default run
/// (4 modes × 5 repetitions) stays in a few seconds.
pub const DEFAULT_STEPS: u64 = 5000;

/// The experiment's options.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExperimentOptions {
    /// Steps per run (one second of sim time each on grid004).
    pub steps: u64,
    /// Runs per mode. Paper: 5.
    pub repetitions: usize,
    /// Steps between two samples of the metrics.
    pub sample_every: u64,
    /// The base seed every run's seed derives from.
    pub seed: u64,
    /// Worker threads; 0 for one per core.
    pub threads: usize,
    /// The modes compared, in output order.
    pub modes: Vec<Mode>,
    /// The explorer's parameters; `cell_command` is set from the scenario.
    pub explorer: ExplorerParams,
    /// The change map's parameters; `observation_period_s` is set from the scenario
    /// (its `time.step_s`: one observation per step).
    pub map: MapParams,
}

impl Default for ExperimentOptions {
    fn default() -> Self {
        ExperimentOptions {
            steps: DEFAULT_STEPS,
            repetitions: 5,
            sample_every: 10,
            seed: 0,
            threads: 0,
            modes: Mode::ALL.to_vec(),
            explorer: ExplorerParams::default(),
            map: MapParams::default(),
        }
    }
}

impl ExperimentOptions {
    pub fn check(&self) -> Result<(), MappingError> {
        let bad = |field: &'static str, reason: String| Err(MappingError::Option { field, reason });
        if self.steps == 0 || self.steps > MAX_STEPS {
            return bad(
                "steps",
                format!(
                    "must be 1 to {MAX_STEPS} (limit max_steps), got {}",
                    self.steps
                ),
            );
        }
        if self.repetitions == 0 || self.repetitions > MAX_REPETITIONS {
            return bad(
                "repetitions",
                format!(
                    "must be 1 to {MAX_REPETITIONS} (limit max_repetitions), got {}",
                    self.repetitions
                ),
            );
        }
        if self.sample_every == 0 || self.steps / self.sample_every + 2 > MAX_SAMPLES {
            return bad(
                "sample_every",
                format!(
                    "must be at least 1 and give at most {MAX_SAMPLES} samples (limit \
                     max_samples): steps / sample_every = {} / {}",
                    self.steps, self.sample_every
                ),
            );
        }
        if self.threads > MAX_THREADS {
            return bad(
                "threads",
                format!(
                    "at most {MAX_THREADS} (limit max_threads), got {}",
                    self.threads
                ),
            );
        }
        if self.modes.is_empty() || self.modes.len() > Mode::ALL.len() {
            return bad("modes", format!("give one to {} modes", Mode::ALL.len()));
        }
        self.explorer.check().map_err(MappingError::Mapper)
    }
}

/// Why the experiment could not run.
#[derive(Debug, thiserror::Error)]
pub enum MappingError {
    #[error("option {field}: {reason}")]
    Option { field: &'static str, reason: String },
    #[error("scenario: {0}")]
    Scenario(String),
    #[error("true rates: {0}")]
    Truth(#[from] TruthError),
    #[error("sim: {0}")]
    Sim(#[from] SimError),
    #[error("mapper: {0}")]
    Mapper(#[from] MapperError),
    #[error("writing {path}: {reason}")]
    Io { path: String, reason: String },
}

/// The built-in grid004 scenario.
pub fn grid004() -> Result<Scenario, MappingError> {
    scenario::parse(Path::new(GRID004_NAME), GRID004, MAX_MAP_CELLS)
        .map_err(|e| MappingError::Scenario(e.to_string()))
}
