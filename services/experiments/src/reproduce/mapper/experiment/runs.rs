//! One run of one mode: the sim stepped, the map fed, the explorer asked, the curves
//! sampled; its seed, and a traced run's view of each step.

use roam_mapper::change_map::{ChangeMap, MapParams};
use roam_mapper::error::MapperError;
use roam_mapper::explorer::{Explorer, ExplorerParams, ExplorerStep};
use roam_mapper::learner::Mode;
use roam_sim::{Command, Sim};
use roam_world::scenario::Scenario;
use roam_world::seed;

use crate::reproduce::mapper::truth::{true_rates, TrueRates};

use super::metrics::{map_quality_of, rate_error_of, trapezoid};
use super::options::{ExperimentOptions, MappingError};
use super::output::RunSummary;

/// One run's summary, curves and rewards, as [`super::run`] averages them.
pub(super) struct RunResult {
    pub(super) summary: RunSummary,
    pub(super) rate_error: Vec<f64>,
    pub(super) map_quality: Vec<f64>,
    pub(super) time_s: Vec<f64>,
    pub(super) rewards: (f64, u64),
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

/// One run of `mode`, repetition `repetition`, as [`run`](super::run) makes it, calling
/// `watch` after every step (for tests and measurements of the runs' insides).
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

pub(super) fn run_one(
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
