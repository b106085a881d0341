//! Paper 002 §4, ES3: two robots in a fully covered disk (one anchor in the middle, six on
//! its 30 m range), `missions` random missions (paper: 10), `runs` runs each (paper:
//! 100), z_is = 0.9, the controllers on position estimates. For each scheme and mission
//! the mean RMSE, steps (until both robots are done) and distance (both robots) are
//! normalised to traditional APF's on the same mission as a percentage change, then
//! averaged over the missions.
//!
//! **Missions** (paper 002: "each of the robots starts on the left and right side of the
//! coverage area and has to pass from three randomly placed waypoints"). Each robot gets
//! three waypoints drawn uniformly (by area) from the disk of [`DISK_RADIUS_M`] around
//! the middle anchor (the anchor named `middle`, else the anchors' centroid), redrawn
//! until the waypoint is at least [`MIN_ANCHOR_CLEARANCE_M`] from every anchor (the PEB
//! and its gradient are at their most irregular next to an anchor), at least η_thres
//! from every obstacle (no repulsion at a waypoint) and at least [`MIN_LEG_M`] from the
//! robot's previous point (its start, then its previous waypoint), so every leg is a real
//! leg. Mission m draws from its own ChaCha8 stream keyed by the base seed and m.
//!
//! **Normalisation.** Per mission, a scheme's mean is compared with plain APF's mean on
//! that mission: 100 · (scheme − plain)/plain. Steps and distance are means over the
//! successful runs; a mission where either side has no successful run (or plain's value
//! is 0) is left out of that metric's average, and `missions_compared` says how many
//! were used. Beside them, `failures` counts the failed runs and `steps_all_change_pct`
//! makes the same comparison over all runs, failed ones included at the step where they
//! were given up.

use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roam_world::noise::uniform;
use roam_world::scenario::Scenario;
use serde::Serialize;

use super::error::ApfError;
use super::failure::FailureCauses;
use super::runs::{run_parallel, run_seed, RunOptions};
use super::summary::{summarize, RunSummary, Summary};
use crate::closed_loop::episode::{run_episode, PositionSource, RobotMission, Setup};
use crate::progress::Done;
use roam_controller::params::ApfParams;
use roam_controller::weights::Scheme;

/// Paper 002 §4 ES3: z_is = 0.9.
pub const Z_IS: f64 = 0.9;
/// Waypoints are drawn within this distance of the middle anchor, metres: 5 m inside its
/// 30 m range, where every point hears three or four anchors.
pub const DISK_RADIUS_M: f64 = 25.0;
/// A waypoint is at least this far from every anchor, metres.
pub const MIN_ANCHOR_CLEARANCE_M: f64 = 3.0;
/// A waypoint is at least this far from the robot's previous point, metres.
pub const MIN_LEG_M: f64 = 5.0;
/// Waypoints per robot (paper 002: three).
pub const WAYPOINTS_PER_ROBOT: usize = 3;
/// Draws per waypoint before the scenario counts as unable to hold a mission.
pub const MAX_DRAWS: usize = 100_000;

/// One scheme's ES3 results, averaged over the missions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Es3Row {
    pub scheme: Scheme,
    /// Mean over missions of the mission RMSE's change against plain APF, %.
    pub rmse_change_pct: Option<f64>,
    /// Mean over missions of the mean steps' change against plain APF, %.
    pub steps_change_pct: Option<f64>,
    /// Mean over missions of the mean distance's change against plain APF, %.
    pub distance_change_pct: Option<f64>,
    /// Share of all its runs in which both robots reached all their waypoints.
    pub success_rate: f64,
    /// Mean over missions of the mission RMSE, metres.
    pub rmse_m: Option<f64>,
    /// Mean over missions of the mean steps of the successful runs.
    pub steps: Option<f64>,
    /// Mean over missions of the mean distance (both robots) of the successful runs.
    pub distance_m: Option<f64>,
    /// Missions in the steps average (both sides had a successful run).
    pub missions_compared: usize,
    /// Runs (over all missions) in which a robot missed a waypoint.
    pub failures: usize,
    /// Mean over missions of the change of the mean steps of ALL runs (a failed run
    /// until it was given up, e.g. at the step limit) against plain APF's, %: beside
    /// `steps_change_pct`, which leaves failed runs out.
    pub steps_all_change_pct: Option<f64>,
    /// The failed runs (over all missions) by cause ([`super::failure`]).
    pub causes: FailureCauses,
}

/// ES3's rows (one per scheme, plain first), the missions, and every (scheme, mission)
/// summary (scheme-major).
#[derive(Debug, Clone, PartialEq)]
pub struct Es3Outcome {
    pub rows: Vec<Es3Row>,
    pub missions: Vec<Vec<RobotMission>>,
    pub summaries: Vec<(Scheme, usize, Summary)>,
}

/// The centre of the waypoint disk: the anchor named `middle`, else the anchors'
/// centroid; `None` without anchors.
fn centre(setup: &Setup) -> Option<[f64; 2]> {
    let anchors = &setup.scenario.file.anchors;
    if let Some(m) = anchors.iter().find(|a| a.name == "middle") {
        return Some(m.at);
    }
    let n = anchors.len();
    (n > 0).then(|| {
        let (x, y) = anchors
            .iter()
            .fold((0.0, 0.0), |(x, y), a| (x + a.at[0], y + a.at[1]));
        [x / n as f64, y / n as f64]
    })
}

/// The `count` random missions of ES3 (module doc) for every robot of the scenario.
pub fn sample_missions(
    setup: &Setup,
    params: &ApfParams,
    count: usize,
    seed: u64,
) -> Result<Vec<Vec<RobotMission>>, ApfError> {
    let bad = |reason: String| ApfError::Scenario {
        scenario: setup.scenario.file.name.clone(),
        reason,
    };
    let c = centre(setup).ok_or_else(|| bad("ES3 needs anchors".into()))?;
    let anchors: Vec<[f64; 2]> = setup.scenario.file.anchors.iter().map(|a| a.at).collect();
    let ok = |p: [f64; 2], previous: [f64; 2]| {
        anchors
            .iter()
            .all(|a| (a[0] - p[0]).hypot(a[1] - p[1]) >= MIN_ANCHOR_CLEARANCE_M)
            && setup.obstacles.distance_m(p) >= params.eta_thres_m
            && (previous[0] - p[0]).hypot(previous[1] - p[1]) >= MIN_LEG_M
    };
    let mut out = Vec::with_capacity(count);
    for m in 0..count {
        let label = format!("es3/missions/{m}");
        let mut rng = ChaCha8Rng::seed_from_u64(roam_world::seed::labelled(seed, &label));
        let mut mission = Vec::new();
        for robot in &setup.scenario.file.robots {
            let mut previous = robot.at;
            let mut waypoints = Vec::with_capacity(WAYPOINTS_PER_ROBOT);
            for _ in 0..WAYPOINTS_PER_ROBOT {
                let mut found = None;
                for _ in 0..MAX_DRAWS {
                    let r = DISK_RADIUS_M * uniform(&mut rng).sqrt();
                    let theta = std::f64::consts::TAU * uniform(&mut rng);
                    let p = [c[0] + r * theta.cos(), c[1] + r * theta.sin()];
                    if ok(p, previous) {
                        found = Some(p);
                        break;
                    }
                }
                let p = found.ok_or_else(|| {
                    bad(format!(
                        "no waypoint for robot '{}' in {MAX_DRAWS} draws",
                        robot.name
                    ))
                })?;
                waypoints.push(p);
                previous = p;
            }
            mission.push(RobotMission {
                robot: robot.name.clone(),
                waypoints,
            });
        }
        out.push(mission);
    }
    Ok(out)
}

fn change_pct(value: Option<f64>, plain: Option<f64>) -> Option<f64> {
    match (value, plain) {
        (Some(v), Some(p)) if p != 0.0 => Some(100.0 * (v - p) / p),
        _ => None,
    }
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// Runs ES3 on `scenario` (roam's `config/scenarios/es3.yaml`, two robots) with
/// `missions` random missions and `options.runs` runs per mission and scheme.
pub fn es3(
    scenario: &Scenario,
    options: &RunOptions<'_>,
    missions: usize,
) -> Result<Es3Outcome, ApfError> {
    options.check()?;
    if !(1..=super::runs::MAX_MISSIONS).contains(&missions) {
        return Err(ApfError::BadOption {
            name: "missions",
            value: missions,
            expected: "use 1 to 10000 missions",
        });
    }
    let setup = Setup::new(scenario)?;
    let mission_list = sample_missions(&setup, options.params, missions, options.seed)?;
    let params = |scheme| ApfParams {
        scheme,
        z_is: Z_IS,
        ..options.params.clone()
    };
    let jobs: Vec<(Scheme, usize, usize)> = Scheme::ALL
        .iter()
        .flat_map(|&s| (0..missions).flat_map(move |m| (0..options.runs).map(move |r| (s, m, r))))
        .collect();
    let total = jobs.len();
    let results = run_parallel(
        &jobs,
        options.threads,
        |&(scheme, m, run)| {
            let seed = run_seed(options.seed, "es3", m, run);
            run_episode(
                &setup,
                &params(scheme),
                PositionSource::Estimate,
                &mission_list[m],
                seed,
            )
            .map(|e| RunSummary::of(&e, &setup))
        },
        |done| (options.progress)(Done::of("es3", "runs", done, total)),
    );
    let mut results = results.into_iter();
    let mut summaries = Vec::new();
    for scheme in Scheme::ALL {
        for m in 0..missions {
            let runs = results
                .by_ref()
                .take(options.runs)
                .collect::<Result<Vec<_>, _>>()?;
            summaries.push((scheme, m, summarize(&runs)));
        }
    }
    let of = |scheme: Scheme| summaries.iter().filter(move |(s, _, _)| *s == scheme);
    let plain: Vec<&Summary> = of(Scheme::Plain).map(|(_, _, s)| s).collect();
    let rows = Scheme::ALL
        .iter()
        .map(|&scheme| {
            let mine: Vec<&Summary> = of(scheme).map(|(_, _, s)| s).collect();
            let pairs = || mine.iter().zip(&plain);
            let runs: usize = mine.iter().map(|s| s.runs).sum();
            let succeeded: f64 = mine.iter().map(|s| s.success_rate * s.runs as f64).sum();
            Es3Row {
                scheme,
                rmse_change_pct: mean(pairs().filter_map(|(s, p)| change_pct(s.rmse_m, p.rmse_m))),
                steps_change_pct: mean(pairs().filter_map(|(s, p)| change_pct(s.steps, p.steps))),
                distance_change_pct: mean(
                    pairs().filter_map(|(s, p)| change_pct(s.distance_m, p.distance_m)),
                ),
                success_rate: if runs == 0 {
                    0.0
                } else {
                    succeeded / runs as f64
                },
                rmse_m: mean(mine.iter().filter_map(|s| s.rmse_m)),
                steps: mean(mine.iter().filter_map(|s| s.steps)),
                distance_m: mean(mine.iter().filter_map(|s| s.distance_m)),
                missions_compared: pairs()
                    .filter(|(s, p)| change_pct(s.steps, p.steps).is_some())
                    .count(),
                failures: mine.iter().map(|s| s.failures).sum(),
                steps_all_change_pct: mean(
                    pairs().filter_map(|(s, p)| change_pct(s.steps_all, p.steps_all)),
                ),
                causes: mine
                    .iter()
                    .fold(FailureCauses::default(), |a, s| a.plus(&s.causes)),
            }
        })
        .collect();
    Ok(Es3Outcome {
        rows,
        missions: mission_list,
        summaries,
    })
}
