//! `roam reproduce mapper`: paper 004 §5's grid-world experiment (Fig. 3).
//!
//! The shipped grid world `config/scenarios/grid004.yaml` (25 × 25 cells of 1 m, the
//! robot at the centre, the two blocks with the paper's periods), `repetitions` runs
//! (paper: 5) of `steps` steps for each mode: curious (the learner picks), recency only,
//! Poisson only (the paper's three), and the uniform mix (roam's baseline for the
//! learner: 50/50 each episode). Each run: the sim steps, the robot's observation goes
//! into a fresh [`ChangeMap`], its [`Explorer`] answers the next command; the robot's
//! cell is the sim's true pose (the paper's noise-free odometry).
//!
//! **Seeds and common random numbers.** Repetition r's seed is
//! `seed::derive(options.seed, [r])` ([`run_seed`]) for *every* mode: the mode is left
//! out on purpose, so the modes are compared on the same random numbers rather than on
//! different ones (with the mode in the seed, a difference between two modes would mix
//! their effect with their luck, and 5 repetitions are few to average luck out).
//! The sim and the explorer take their own labelled streams of that seed (the sim's
//! `"world"` and `"robot/<name>"`, the explorer's `"tiles"` and `"explorer/…"`, see
//! [`roam_world::seed`] and [`roam_mapper::explorer`]), so no consumer's draws depend on another's:
//! the sim's world is the same in every mode (on grid004 the blocks are scripted and
//! the motion noise-free, so it is the same anyway), the tilings are the same, and
//! episode k's strategy draw is the same number in every mode. Curious and the uniform
//! mix therefore make the same choice in every episode where the learner's P(recency)
//! lies on the same side of that draw as 1/2, and two modes run step for step alike
//! until their first different choice (the robots' paths part then, and with them the
//! goal and random-step draws). Runs are spread over threads but stored by run, so the
//! output is the same for any number of threads.
//!
//! **Metrics**, every `sample_every` steps and at t = 0 (the paper's x-axis is not
//! readable; time in seconds of sim time here):
//! - *rate-estimate error*: the mean over the cells whose true rate is above zero of
//!   |1/T^c − true rate| ([`crate::reproduce::mapper::truth`]), events per second. Over all free cells
//!   instead it would be this times (changing cells / free cells) in this noise-free
//!   world (static cells never show an event), so the choice changes no comparison.
//! - *map quality*: the share of all cells whose mapped value equals the true occupancy
//!   now (walls and blocks occupied, the rest free); unknown counts as wrong.
//!
//! Per mode, the curves are averaged over repetitions; `rate_error_auc` is the area
//! under the mean error curve (trapezoids over seconds), `final_map_quality` the mean
//! curve's last value, `mean_map_quality` its time average.
mod metrics;
mod options;
mod output;
mod runs;

use roam_mapper::learner::Mode;
use roam_world::scenario::Scenario;

use crate::parallel::run_in_order;
use crate::progress::{Done, Progress};
use crate::reproduce::mapper::truth::true_rates;

use metrics::mean_curve;
pub use metrics::{map_quality_of, rate_error_of, trapezoid};
pub use options::{
    grid004, ExperimentOptions, MappingError, DEFAULT_STEPS, GRID004, GRID004_NAME,
    MAX_REPETITIONS, MAX_SAMPLES, MAX_STEPS, MAX_THREADS,
};
pub use output::{table, Curve, Reproduction, RunSummary, StrategySummary};
use runs::{run_one, RunResult};
pub use runs::{run_seed, trace, StepView};

/// Runs the experiment on `scenario` (grid004 for the paper's); `progress` is called
/// after each run (mode and repetition, one stage `runs`), from the worker threads.
pub fn run(
    scenario_name: &str,
    scenario: &Scenario,
    options: &ExperimentOptions,
    progress: Progress<'_>,
) -> Result<Reproduction, MappingError> {
    options.check()?;
    let step_s = scenario.file.time.step_s;
    let truth = true_rates(scenario, step_s)?;
    let jobs: Vec<(Mode, usize)> = options
        .modes
        .iter()
        .flat_map(|&m| (0..options.repetitions).map(move |r| (m, r)))
        .collect();
    let threads = match options.threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    }
    .clamp(1, jobs.len().max(1));
    let slots = run_in_order(
        &jobs,
        threads,
        |&(mode, repetition)| run_one(scenario, &truth, options, mode, repetition, &mut |_| {}),
        Result::is_err,
        |done, _| progress(Done::of("runs", "runs", done, jobs.len())),
    );
    let mut results = Vec::with_capacity(jobs.len());
    for slot in slots {
        match slot {
            Some(Ok(r)) => results.push(r),
            Some(Err(e)) => return Err(e),
            None => {
                return Err(MappingError::Option {
                    field: "threads",
                    reason: "a run was skipped after another failed".into(),
                })
            }
        }
    }
    let time_s = results
        .first()
        .map(|r| r.time_s.clone())
        .unwrap_or_default();
    let mut strategies = Vec::new();
    let mut curves = Vec::new();
    for &mode in &options.modes {
        let runs: Vec<&RunResult> = results.iter().filter(|r| r.summary.mode == mode).collect();
        let rate_error = mean_curve(runs.iter().map(|r| r.rate_error.as_slice()));
        let map_quality = mean_curve(runs.iter().map(|r| r.map_quality.as_slice()));
        let duration =
            time_s.last().copied().unwrap_or(0.0) - time_s.first().copied().unwrap_or(0.0);
        let (recency, poisson) = runs.iter().fold((0, 0), |(a, b), r| {
            (
                a + r.summary.recency_episodes,
                b + r.summary.poisson_episodes,
            )
        });
        let (reward_sum, reward_n) = runs
            .iter()
            .fold((0.0, 0), |(s, n), r| (s + r.rewards.0, n + r.rewards.1));
        strategies.push(StrategySummary {
            name: mode.as_str().to_owned(),
            rate_error_auc: trapezoid(&time_s, &rate_error),
            final_map_quality: map_quality.last().copied().unwrap_or(0.0),
            mean_map_quality: if duration > 0.0 {
                trapezoid(&time_s, &map_quality) / duration
            } else {
                map_quality.first().copied().unwrap_or(0.0)
            },
            final_rate_error: rate_error.last().copied().unwrap_or(0.0),
            recency_share: recency as f64 / (recency + poisson).max(1) as f64,
            mean_reward: reward_sum / reward_n.max(1) as f64,
        });
        curves.push(Curve {
            name: mode.as_str().to_owned(),
            rate_error,
            map_quality,
        });
    }
    Ok(Reproduction {
        scenario: scenario_name.to_owned(),
        options: options.clone(),
        changing_cells: truth.changing.len(),
        mean_true_rate: truth.mean_changing(),
        strategies,
        time_s,
        curves,
        runs: results.into_iter().map(|r| r.summary).collect(),
    })
}
