//! One configuration's results (goal, split, model), as the JSON names them.

use serde::Serialize;

/// One configuration's results, as the JSON names them.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    pub goal: String,
    pub ratio: String,
    pub model: String,
    pub u_ges_median: f64,
    pub u_ges_mean: f64,
    pub d_median: f64,
    pub distinct_information_median: f64,
    /// Share of runs whose t_ETA fits t_exec.
    pub within_budget: f64,
    /// Share of runs whose path ends at the goal.
    pub reached_goal: f64,
    pub generations: u32,
    pub t_exec_s: f64,
}
