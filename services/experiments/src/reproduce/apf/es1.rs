//! Paper 002 §4, ES1 (Fig. 2): sparse coverage, one robot from A to B, z_is = 0.8, the
//! controller on position estimates, `runs` runs per scheme (paper: 100). For each
//! scheme: the share of runs that reach B, the mission RMSE, and the mean steps and
//! distance of the successful runs.
//!
//! **First fixes.** The robot's first estimate has no prior, so roam-localization starts
//! Gauss–Newton from the closed-form linearised solution. At A the three anchors in range
//! are a1 and the close pair a2, a4, which A sees in almost one direction; in 27 of 2000
//! seeds checked, that first estimate converges to the range equations' second solution
//! (near (29, 58), north of the pair and off the map) and later estimates start from it.
//! With roam's PEB guard on, such a robot is held at A until it is given up; with the
//! guard off it is driven on the wrong position into the map's south wall, out of
//! coverage. Those runs fail whatever the scheme, guard or not (with seed 0, run 8 of
//! every scheme), and are counted apart ([`super::failure`]'s `wrong_first_fix`; paper
//! 002 reports every IS run reaching B).
//!
//! ES1 runs twice, with roam's PEB guard on and off on the same seeds ([`super`]).

use roam_world::scenario::Scenario;
use serde::Serialize;

use super::error::ApfError;
use super::failure::FailureCauses;
use super::runs::{run_parallel, run_seed, RunOptions};
use super::summary::{summarize, RunSummary};
use super::trajectory::Trajectory;
use crate::closed_loop::episode::{mission_from_waypoints, run_episode, PositionSource, Setup};
use crate::progress::Done;
use roam_controller::params::ApfParams;
use roam_controller::weights::Scheme;

/// Paper 002 §4 ES1: z_is = 0.8.
pub const Z_IS: f64 = 0.8;

/// One scheme's ES1 results.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Es1Row {
    pub scheme: Scheme,
    /// Whether roam's PEB guard was on (a finite `max_peb_m`); ES1 is run both ways
    /// (see [`super`]).
    pub guard: bool,
    /// Share of runs that reached B.
    pub success_rate: f64,
    /// The mission RMSE of the successful runs (see [`super`]), metres.
    pub rmse_m: Option<f64>,
    /// The mission RMSE of all runs, metres.
    pub rmse_all_m: Option<f64>,
    /// Mean steps of the successful runs; `None` when none succeeded.
    pub steps: Option<f64>,
    /// Mean distance of the successful runs, metres.
    pub distance_m: Option<f64>,
    pub runs: usize,
    /// Runs that did not reach B.
    pub failures: usize,
    /// Mean steps of all runs (a failed run until it was given up).
    pub steps_all: Option<f64>,
    /// Mean distance of all runs, metres.
    pub distance_all_m: Option<f64>,
    /// The failed runs by cause ([`super::failure`]).
    pub causes: FailureCauses,
}

/// ES1's rows (one per scheme, in [`Scheme::ALL`]'s order) and each scheme's first run.
#[derive(Debug, Clone, PartialEq)]
pub struct Es1Outcome {
    pub rows: Vec<Es1Row>,
    pub trajectories: Vec<Trajectory>,
}

/// Runs ES1 on `scenario` (roam's `config/scenarios/es1.yaml`): its first robot, from its
/// start through the scenario's waypoints (the first skipped when the robot stands on
/// it: A), for every scheme.
pub fn es1(scenario: &Scenario, options: &RunOptions<'_>) -> Result<Es1Outcome, ApfError> {
    options.check()?;
    let setup = Setup::new(scenario)?;
    let robot = scenario
        .file
        .robots
        .first()
        .ok_or_else(|| ApfError::Scenario {
            scenario: scenario.file.name.clone(),
            reason: "ES1 needs a robot".into(),
        })?;
    let params = |scheme| ApfParams {
        scheme,
        z_is: Z_IS,
        ..options.params.clone()
    };
    let mission = mission_from_waypoints(&setup, &robot.name, options.params.g_thres_m, false)?;
    let missions = [mission];
    let jobs: Vec<(Scheme, usize)> = Scheme::ALL
        .iter()
        .flat_map(|&s| (0..options.runs).map(move |r| (s, r)))
        .collect();
    let total = jobs.len();
    let results = run_parallel(
        &jobs,
        options.threads,
        |&(scheme, run)| {
            let seed = run_seed(options.seed, "es1", 0, run);
            run_episode(
                &setup,
                &params(scheme),
                PositionSource::Estimate,
                &missions,
                seed,
            )
            .map(|e| {
                let example = (run == 0).then(|| Trajectory::of(scheme, Z_IS, &e));
                (RunSummary::of(&e, &setup), example)
            })
        },
        |done| (options.progress)(Done::of("es1", "runs", done, total)),
    );
    let mut rows = Vec::new();
    let mut trajectories = Vec::new();
    let mut results = results.into_iter();
    for scheme in Scheme::ALL {
        let (runs, examples): (Vec<RunSummary>, Vec<_>) = results
            .by_ref()
            .take(options.runs)
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .unzip();
        trajectories.extend(examples.into_iter().flatten().flatten());
        let s = summarize(&runs);
        rows.push(Es1Row {
            scheme,
            guard: options.params.max_peb_m.is_finite(),
            success_rate: s.success_rate,
            rmse_m: s.rmse_m,
            rmse_all_m: s.rmse_all_m,
            steps: s.steps,
            distance_m: s.distance_m,
            runs: s.runs,
            failures: s.failures,
            steps_all: s.steps_all,
            distance_all_m: s.distance_all_m,
            causes: s.causes,
        });
    }
    Ok(Es1Outcome { rows, trajectories })
}
