//! Runs summed up: one run reduced to what the summaries need, and the summary of one
//! configuration's runs (the module doc of `apf` says how).

use serde::Serialize;

use super::failure::{self, FailureCause, FailureCauses};
use crate::closed_loop::episode::{Episode, Setup};

/// One run reduced to what the summaries need.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    pub success: bool,
    /// Sim steps until every robot's mission ended (completed or given up).
    pub steps: u64,
    /// The robots' true path lengths, summed, metres.
    pub distance_m: f64,
    /// The squared localization error at each step, averaged over the robots still on
    /// their missions then (module doc).
    pub squared_error: Vec<f64>,
    /// Why the run failed ([`failure`]); `None` when it succeeded.
    pub failure: Option<FailureCause>,
    /// Scans localization refused ([`Episode::localization_errors`]).
    pub localization_errors: u64,
}

impl RunSummary {
    /// `episode` summarised; `setup` is its scenario's, for the coverage where a failed
    /// robot ended.
    pub fn of(episode: &Episode, setup: &Setup) -> RunSummary {
        let longest = episode
            .robots
            .iter()
            .map(|r| r.error_m.len())
            .max()
            .unwrap_or(0);
        let squared_error = (0..longest)
            .map(|k| {
                let (sum, n) = episode
                    .robots
                    .iter()
                    .filter_map(|r| r.error_m.get(k))
                    .fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
                sum / n.max(1) as f64
            })
            .collect();
        RunSummary {
            success: episode.success(),
            steps: episode.robots.iter().map(|r| r.steps).max().unwrap_or(0),
            distance_m: episode.robots.iter().map(|r| r.distance_m).sum(),
            squared_error,
            failure: failure::cause(episode, setup),
            localization_errors: episode.localization_errors,
        }
    }
}

/// The summary of one configuration's runs (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    pub runs: usize,
    /// Share of runs in which every robot reached every waypoint.
    pub success_rate: f64,
    /// The mission RMSE of the successful runs (module doc), metres.
    pub rmse_m: Option<f64>,
    /// The mission RMSE of all runs, metres; `None` without any sample.
    pub rmse_all_m: Option<f64>,
    /// Mean steps of the successful runs.
    pub steps: Option<f64>,
    /// Mean distance of the successful runs, metres.
    pub distance_m: Option<f64>,
    /// Runs in which some robot missed a waypoint.
    pub failures: usize,
    /// Mean steps of all runs (failed runs until given up).
    pub steps_all: Option<f64>,
    /// Mean distance of all runs, metres.
    pub distance_all_m: Option<f64>,
    /// The failed runs by cause ([`failure`]).
    pub causes: FailureCauses,
}

/// The paper's mission RMSE over `runs` (module doc): RMSE^k over the runs still going
/// at k, averaged over k; `None` without any sample.
fn mission_rmse(runs: &[&RunSummary]) -> Option<f64> {
    let longest = runs
        .iter()
        .map(|r| r.squared_error.len())
        .max()
        .unwrap_or(0);
    let sum: f64 = (0..longest)
        .map(|k| {
            let (sum, n) = runs
                .iter()
                .filter_map(|r| r.squared_error.get(k))
                .fold((0.0, 0usize), |(s, n), e| (s + e, n + 1));
            (sum / n.max(1) as f64).sqrt()
        })
        .sum();
    (longest > 0).then(|| sum / longest as f64)
}

/// Summarises runs given in run order (module doc).
pub fn summarize(runs: &[RunSummary]) -> Summary {
    let ok: Vec<&RunSummary> = runs.iter().filter(|r| r.success).collect();
    let mean = |values: Vec<f64>| {
        (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
    };
    Summary {
        runs: runs.len(),
        success_rate: if runs.is_empty() {
            0.0
        } else {
            ok.len() as f64 / runs.len() as f64
        },
        rmse_m: mission_rmse(&ok),
        rmse_all_m: mission_rmse(&runs.iter().collect::<Vec<_>>()),
        steps: mean(ok.iter().map(|r| r.steps as f64).collect()),
        distance_m: mean(ok.iter().map(|r| r.distance_m).collect()),
        failures: runs.len() - ok.len(),
        steps_all: mean(runs.iter().map(|r| r.steps as f64).collect()),
        distance_all_m: mean(runs.iter().map(|r| r.distance_m).collect()),
        causes: FailureCauses {
            localization_errors: runs.iter().map(|r| r.localization_errors).sum(),
            ..FailureCauses::count(runs.iter().filter_map(|r| r.failure))
        },
    }
}
