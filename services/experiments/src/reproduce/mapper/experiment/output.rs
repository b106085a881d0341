//! The reproduction's output: per-mode summaries and mean curves, the runs, and the
//! plain-text table.

use roam_mapper::learner::Mode;
use serde::Serialize;

use super::options::ExperimentOptions;

/// One mode's summary: the JSON's `strategies` entries.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StrategySummary {
    /// `curious`, `recency`, `poisson` or `uniform`.
    pub name: String,
    /// Area under the mean rate-error curve, (events/s)·s.
    pub rate_error_auc: f64,
    /// The mean map-quality curve's last value.
    pub final_map_quality: f64,
    /// The mean map-quality curve's time average.
    pub mean_map_quality: f64,
    /// The mean rate-error curve's last value, events/s.
    pub final_rate_error: f64,
    /// Share of episodes that used the recency strategy (1 or 0 for the fixed modes).
    pub recency_share: f64,
    /// Mean episode reward (map changes per step).
    pub mean_reward: f64,
}

/// One mode's mean curves, sampled at [`Reproduction::time_s`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    pub name: String,
    pub rate_error: Vec<f64>,
    pub map_quality: Vec<f64>,
}

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummary {
    pub mode: Mode,
    pub repetition: usize,
    pub seed: u64,
    pub rate_error_auc: f64,
    pub final_rate_error: f64,
    pub final_map_quality: f64,
    pub episodes: u64,
    /// Episodes started with each strategy.
    pub recency_episodes: u64,
    pub poisson_episodes: u64,
    pub mean_reward: f64,
}

/// The reproduction's output.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reproduction {
    pub scenario: String,
    pub options: ExperimentOptions,
    /// Cells whose true rate is above zero, and their mean true rate (events/s).
    pub changing_cells: usize,
    pub mean_true_rate: f64,
    pub strategies: Vec<StrategySummary>,
    /// The sample times, seconds.
    pub time_s: Vec<f64>,
    pub curves: Vec<Curve>,
    pub runs: Vec<RunSummary>,
}

/// The plain-text table for the terminal.
pub fn table(r: &Reproduction) -> String {
    let mut out = format!(
        "paper 004 §5 on {}: {} runs of {} steps per mode, {} changing cells (mean true \
         rate {:.4}/s)\n",
        r.scenario, r.options.repetitions, r.options.steps, r.changing_cells, r.mean_true_rate
    );
    out.push_str(&format!(
        "{:<9} {:>15} {:>16} {:>12} {:>17} {:>14} {:>11}\n",
        "strategy",
        "rate err AUC",
        "final rate err",
        "final map q",
        "mean map quality",
        "recency share",
        "mean reward"
    ));
    for s in &r.strategies {
        out.push_str(&format!(
            "{:<9} {:>15.3} {:>16.5} {:>12.3} {:>17.3} {:>14.2} {:>11.3}\n",
            s.name,
            s.rate_error_auc,
            s.final_rate_error,
            s.final_map_quality,
            s.mean_map_quality,
            s.recency_share,
            s.mean_reward
        ));
    }
    out
}
