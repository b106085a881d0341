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
//! different ones (issue 18: with the mode in the seed, a difference between two modes
//! mixed their effect with their luck, and 5 repetitions are few to average luck out).
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

use std::path::Path;

use crate::parallel::run_in_order;
use crate::progress::{Done, Progress};

use roam_sim::{Command, Sim, SimError};
use roam_world::scenario::{self, Scenario};
use serde::Serialize;

use crate::reproduce::mapper::truth::{true_rates, TrueRates, TruthError};
use roam_mapper::change_map::{ChangeMap, MapParams, MAX_MAP_CELLS};
use roam_mapper::error::MapperError;
use roam_mapper::explorer::{Explorer, ExplorerParams, ExplorerStep};
use roam_mapper::learner::Mode;
use roam_world::seed;

/// The shipped grid world, built in.
pub const GRID004_NAME: &str = "grid004.yaml";
pub const GRID004: &str = include_str!("../../../../../config/scenarios/grid004.yaml");

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

/// The built-in grid004 scenario.
pub fn grid004() -> Result<Scenario, MappingError> {
    scenario::parse(Path::new(GRID004_NAME), GRID004, MAX_MAP_CELLS)
        .map_err(|e| MappingError::Scenario(e.to_string()))
}

struct RunResult {
    summary: RunSummary,
    rate_error: Vec<f64>,
    map_quality: Vec<f64>,
    time_s: Vec<f64>,
    rewards: (f64, u64),
}

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

/// The seed of repetition `repetition`, the same for every mode (common random
/// numbers, module doc).
pub fn run_seed(base: u64, repetition: usize) -> u64 {
    seed::derive(base, &[repetition as u64])
}

/// What a traced run shows after each step: the sim after the step, the map after the
/// robot's observation, the explorer and its answer.
#[derive(Debug)]
pub struct StepView<'a> {
    pub step: u64,
    pub sim: &'a Sim,
    pub map: &'a ChangeMap,
    pub explorer: &'a Explorer,
    pub next: &'a ExplorerStep,
}

/// One run of `mode`, repetition `repetition`, as [`run`] makes it, calling `watch`
/// after every step (for tests and measurements of the runs' insides).
pub fn trace(
    scenario: &Scenario,
    options: &ExperimentOptions,
    mode: Mode,
    repetition: usize,
    watch: &mut dyn FnMut(StepView),
) -> Result<RunSummary, MappingError> {
    options.check()?;
    let truth = true_rates(scenario, scenario.file.time.step_s)?;
    run_one(scenario, &truth, options, mode, repetition, watch).map(|r| r.summary)
}

fn run_one(
    scenario: &Scenario,
    truth: &TrueRates,
    options: &ExperimentOptions,
    mode: Mode,
    repetition: usize,
    watch: &mut dyn FnMut(StepView),
) -> Result<RunResult, MappingError> {
    let seed = run_seed(options.seed, repetition);
    let mut sim = Sim::new(scenario, seed)?;
    let robot = scenario
        .file
        .robots
        .first()
        .map(|r| r.name.clone())
        .ok_or_else(|| MappingError::Scenario("the scenario has no robot".into()))?;
    let meta = scenario.occupancy.meta;
    let step_s = sim.params().time.step_s;
    let mut map = ChangeMap::new(
        meta,
        MapParams {
            observation_period_s: step_s,
            ..options.map
        },
    )?;
    let params = ExplorerParams {
        cell_command: meta.resolution / sim.params().motion.step_mu,
        ..options.explorer
    };
    let mut explorer = Explorer::new(params, mode, seed)?;
    let mut time_s = vec![0.0];
    let mut rate_error = vec![rate_error_of(&map, truth)];
    let mut map_quality = vec![0.0];
    let mut u = [0.0, 0.0];
    let (mut reward_sum, mut reward_n) = (0.0, 0u64);
    for step in 1..=options.steps {
        let report = sim.step(&[Command {
            robot: robot.clone(),
            u,
        }])?;
        let Some(readings) = report
            .robots
            .iter()
            .find(|r| r.name == robot)
            .map(|r| &r.readings)
        else {
            return Err(MappingError::Scenario(format!("robot '{robot}' vanished")));
        };
        let Some(observation) = &readings.observation else {
            return Err(MappingError::Scenario(
                "the scenario has no observation (sensing.observation_radius_m is 0)".into(),
            ));
        };
        let update = map.observe(&observation.into(), report.time_s)?;
        let cell = map.cell_of(readings.truth).ok_or(MapperError::CellOffMap {
            x: readings.truth[0].floor() as i64,
            y: readings.truth[1].floor() as i64,
            width: meta.width,
            height: meta.height,
        })?;
        let next = explorer.on_update(&mut map, &update, cell, report.time_s)?;
        if let Some(end) = next.episode {
            reward_sum += end.reward;
            reward_n += 1;
        }
        u = next.u;
        watch(StepView {
            step,
            sim: &sim,
            map: &map,
            explorer: &explorer,
            next: &next,
        });
        if step % options.sample_every == 0 || step == options.steps {
            time_s.push(report.time_s);
            rate_error.push(rate_error_of(&map, truth));
            map_quality.push(map_quality_of(&map, &sim));
        }
    }
    let [recency_episodes, poisson_episodes] = explorer.strategy_counts();
    Ok(RunResult {
        summary: RunSummary {
            mode,
            repetition,
            seed,
            rate_error_auc: trapezoid(&time_s, &rate_error),
            final_rate_error: rate_error.last().copied().unwrap_or(0.0),
            final_map_quality: map_quality.last().copied().unwrap_or(0.0),
            episodes: explorer.episodes_ended(),
            recency_episodes,
            poisson_episodes,
            mean_reward: reward_sum / reward_n.max(1) as f64,
        },
        rate_error,
        map_quality,
        time_s,
        rewards: (reward_sum, reward_n),
    })
}

/// Mean over the changing cells of |estimated − true rate|.
pub fn rate_error_of(map: &ChangeMap, truth: &TrueRates) -> f64 {
    if truth.changing.is_empty() {
        return 0.0;
    }
    let processes = map.processes();
    let sum: f64 = truth
        .changing
        .iter()
        .map(|&i| {
            let estimate = processes.get(i).map_or(0.0, |p| p.rate());
            (estimate - truth.rates[i]).abs()
        })
        .sum();
    sum / truth.changing.len() as f64
}

/// Share of cells whose mapped value is the true occupancy now.
pub fn map_quality_of(map: &ChangeMap, sim: &Sim) -> f64 {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let world = sim.world();
    let mut right = 0usize;
    for y in 0..h {
        for x in 0..w {
            let truth = if world.is_blocked((x as i64, y as i64)) {
                100
            } else {
                0
            };
            right += usize::from(map.obstacles()[y * w + x] == truth);
        }
    }
    right as f64 / (w * h).max(1) as f64
}

fn mean_curve<'a>(curves: impl Iterator<Item = &'a [f64]>) -> Vec<f64> {
    let mut sum: Vec<f64> = Vec::new();
    let mut n = 0usize;
    for c in curves {
        if sum.is_empty() {
            sum = vec![0.0; c.len()];
        }
        for (s, v) in sum.iter_mut().zip(c) {
            *s += v;
        }
        n += 1;
    }
    sum.iter().map(|s| s / n.max(1) as f64).collect()
}

/// ∫ y dt by trapezoids.
pub fn trapezoid(t: &[f64], y: &[f64]) -> f64 {
    t.windows(2)
        .zip(y.windows(2))
        .map(|(t, y)| (t[1] - t[0]) * (y[0] + y[1]) / 2.0)
        .sum()
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
