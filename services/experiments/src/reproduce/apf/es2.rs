//! Paper 002 §4, ES2 (Fig. 3): one robot from A through B, C and D back to A, the
//! controller on TRUE positions ("nominal conditions"), z_is from 0.0 to 0.9 for the
//! fixed, cutoff, linear and sinusoidal schemes (z_is = 0 is traditional APF), `runs`
//! runs each (paper 002 does not say how many; the transition noise differs per run).
//!
//! On true positions a lost fix does not matter, so the PEB guard is off
//! (`max_peb_m = ∞`): the middles of ES2's legs are covered by two anchors nearly in line
//! with the robot, where the PEB is far above roam's default bound.
//!
//! A run's seed depends on the run only, not on the scheme or z_is: the same noise at
//! every point (common random numbers, see [`super`]), so a curve over z_is, and the gap
//! between two schemes' curves, shows their effect rather than the noise's.

use roam_world::scenario::Scenario;
use serde::Serialize;

use super::error::ApfError;
use super::runs::{run_parallel, run_seed, RunOptions};
use super::summary::{summarize, RunSummary};
use super::trajectory::Trajectory;
use crate::closed_loop::episode::{mission_from_waypoints, run_episode, PositionSource, Setup};
use crate::progress::Done;
use roam_controller::params::ApfParams;
use roam_controller::weights::Scheme;

/// Paper 002 §4 ES2: z_is ∈ {0.0, 0.1, …, 0.9}.
pub const Z_IS: [f64; 10] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9];

/// The z_is whose trajectories Fig. 3 (left) shows.
pub const FIGURE_Z_IS: f64 = 0.9;

/// One (scheme, z_is) point of ES2.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Es2Row {
    pub scheme: Scheme,
    pub z_is: f64,
    /// Mean steps of the successful runs.
    pub steps: Option<f64>,
    /// Mean distance of the successful runs, metres.
    pub distance_m: Option<f64>,
    pub success_rate: f64,
    /// The mission RMSE of the estimates made along the way (the controller does not use
    /// them), successful runs, metres.
    pub rmse_m: Option<f64>,
    pub runs: usize,
}

/// ES2's rows (scheme-major, z_is ascending) and the figure's runs: run 0 of each scheme
/// at [`FIGURE_Z_IS`], and of traditional APF (z_is = 0, labelled `plain`).
#[derive(Debug, Clone, PartialEq)]
pub struct Es2Outcome {
    pub rows: Vec<Es2Row>,
    pub trajectories: Vec<Trajectory>,
}

/// Runs ES2 on `scenario` (roam's `config/scenarios/es2.yaml`): its first robot through
/// the scenario's waypoints and back to the first, for each IS scheme and each z_is of
/// `z_values`.
pub fn es2(
    scenario: &Scenario,
    options: &RunOptions<'_>,
    z_values: &[f64],
) -> Result<Es2Outcome, ApfError> {
    options.check()?;
    let setup = Setup::new(scenario)?;
    let robot = scenario
        .file
        .robots
        .first()
        .ok_or_else(|| ApfError::Scenario {
            scenario: scenario.file.name.clone(),
            reason: "ES2 needs a robot".into(),
        })?;
    let mission = mission_from_waypoints(&setup, &robot.name, options.params.g_thres_m, true)?;
    let missions = [mission];
    let params = |scheme, z_is| ApfParams {
        scheme,
        z_is,
        max_peb_m: f64::INFINITY,
        ..options.params.clone()
    };
    for &z in z_values {
        params(Scheme::Fixed, z).check()?;
    }
    let jobs: Vec<(Scheme, usize, usize)> = Scheme::IS
        .iter()
        .flat_map(|&s| {
            (0..z_values.len()).flat_map(move |z| (0..options.runs).map(move |r| (s, z, r)))
        })
        .collect();
    let total = jobs.len();
    let results = run_parallel(
        &jobs,
        options.threads,
        |&(scheme, z, run)| {
            let z_is = z_values[z];
            let seed = run_seed(options.seed, "es2", 0, run);
            run_episode(
                &setup,
                &params(scheme, z_is),
                PositionSource::Truth,
                &missions,
                seed,
            )
            .map(|e| {
                let example = (run == 0).then(|| {
                    if z_is == FIGURE_Z_IS {
                        Trajectory::of(scheme, z_is, &e)
                    } else if z_is == 0.0 && scheme == Scheme::Fixed {
                        Trajectory::of(Scheme::Plain, 0.0, &e)
                    } else {
                        Vec::new()
                    }
                });
                (RunSummary::of(&e, &setup), example)
            })
        },
        |done| (options.progress)(Done::of("es2", "runs", done, total)),
    );
    let mut rows = Vec::new();
    let mut trajectories = Vec::new();
    let mut results = results.into_iter();
    for scheme in Scheme::IS {
        for &z_is in z_values {
            let (runs, examples): (Vec<RunSummary>, Vec<_>) = results
                .by_ref()
                .take(options.runs)
                .collect::<Result<Vec<_>, _>>()?
                .into_iter()
                .unzip();
            trajectories.extend(examples.into_iter().flatten().flatten());
            let s = summarize(&runs);
            rows.push(Es2Row {
                scheme,
                z_is,
                steps: s.steps,
                distance_m: s.distance_m,
                success_rate: s.success_rate,
                rmse_m: s.rmse_m,
                runs: s.runs,
            });
        }
    }
    // Plain first, then the schemes in order.
    trajectories.sort_by_key(|t| Scheme::ALL.iter().position(|&s| s == t.scheme));
    Ok(Es2Outcome { rows, trajectories })
}
