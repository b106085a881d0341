//! `roam reproduce mission`: the papers joined, in batch (no network), over many seeded
//! missions in the built-in world. Each mission is a downtime trip between two random
//! free places with a budget of twice the shortest path's ETA; it is planned by the
//! curious GA (paper 000, Model I), made into waypoints as the executive makes them
//! (every turn of the cell path kept), and driven by the APF
//! controller on the localization's estimates in the sim (paper 002), exactly the code
//! the services run. What is compared is what the planner is given:
//!
//! - `static`: paper 000 as published, the static information map;
//! - `peb_cost`: the same plus roam's localizability cost, W_loc · Σ PEB along the path,
//!   from the anchors' PEB field (paper 002 into paper 000's fitness);
//! - `change`: the mapper's change probability as the information map (paper 004 into
//!   paper 000): a [`ChangeMap`] watches the whole built-in world for a minute and its
//!   100 · P(E > 0) becomes I_xy. Nothing moves in the built-in world, so that map is
//!   flat zero and the row shows what a change-driven planner does with no news;
//! - `shortest`: the shortest path, for reference.
//!
//! Measured per mission: the information of the distinct cells seen along the path the
//! robot really drove (paper 000's measure on the static map, for every variant), whether
//! it arrived within the budget, and the mean PEB at its true positions; and, against
//! what the plan promised on the same measure, driven / planned information per mission
//! and its median (how closely the plan was driven as planned).

use std::sync::atomic::AtomicBool;

use crate::closed_loop::episode::{run_episode, PositionSource, RobotMission, Setup};
use crate::progress::{Done, Progress};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roam_controller::params::ApfParams;
use roam_localization::field::{peb_field, GridRegion};
use roam_localization::{FimOptions, RangingModel};
use roam_mapper::change_map::{ChangeMap, MapParams, ObservationWindow};
use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use roam_world::layers::inflate;
use roam_world::scenario::{self, Scenario};
use serde::Serialize;

use roam_mission::information::gathered;
use roam_mission::path::{distance, mission_waypoints};

/// How much to run.
#[derive(Debug, Clone)]
pub struct MissionExperiment {
    pub missions: usize,
    pub seed: u64,
    /// GA generations per plan.
    pub generations: u32,
    /// W_loc of the `peb_cost` variant.
    pub w_loc: f64,
}

impl Default for MissionExperiment {
    fn default() -> Self {
        MissionExperiment {
            missions: 20,
            seed: 0,
            generations: 1000,
            w_loc: 2000.0,
        }
    }
}

/// One variant's results over the missions.
#[derive(Debug, Clone, Serialize)]
pub struct VariantResult {
    pub variant: &'static str,
    /// Mean information of the distinct cells seen along the driven paths.
    pub information: f64,
    /// Share of missions that arrived within their budget.
    pub on_time_share: f64,
    /// Mean PEB at the true positions along the way, metres.
    pub peb_mean_m: f64,
    /// Mean information of the planned paths (what the planner promised).
    pub planned_information: f64,
    /// Each mission's information, driven and planned, in the missions' order.
    pub per_mission: Vec<MissionInformation>,
    /// The median over the missions of driven / planned information (the missions whose
    /// plan promised any); `None` when none did.
    pub driven_over_planned_median: Option<f64>,
}

/// One mission's information: what the robot drove against what the plan promised.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct MissionInformation {
    pub driven: f64,
    pub planned: f64,
    /// driven / planned; `None` when the plan promised nothing.
    pub driven_over_planned: Option<f64>,
}

/// The median of `values` (the mean of the middle two for an even count); `None` when
/// empty.
fn median(mut values: Vec<f64>) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(values[n / 2]),
        _ => Some((values[n / 2 - 1] + values[n / 2]) / 2.0),
    }
}

#[derive(Debug, Clone, Serialize)]
pub struct MissionReproduction {
    pub missions: usize,
    pub seed: u64,
    pub variants: Vec<VariantResult>,
}

#[derive(Debug, thiserror::Error)]
pub enum MissionExperimentError {
    #[error("the built-in world: {0}")]
    World(String),
    #[error("planning: {0}")]
    Plan(String),
    #[error("driving: {0}")]
    Drive(String),
}

fn builtin() -> Result<Scenario, MissionExperimentError> {
    scenario::builtin().map_err(|e| MissionExperimentError::World(e.to_string()))
}

const VARIANTS: [&str; 4] = ["static", "peb_cost", "change", "shortest"];

/// The built-in world's information map as the mapper would make it: 100 · P(E > 0)
/// after watching every cell once a second for `seconds`.
fn change_information(
    scenario: &Scenario,
    seconds: u32,
) -> Result<Vec<u8>, MissionExperimentError> {
    let meta = scenario.occupancy.meta;
    let mut map = ChangeMap::new(meta, MapParams::default())
        .map_err(|e| MissionExperimentError::World(e.to_string()))?;
    let window = ObservationWindow {
        x0: 0,
        y0: 0,
        width: meta.width,
        height: meta.height,
        cells: &scenario.occupancy.cells,
    };
    for t in 0..=seconds {
        map.observe(&window, f64::from(t))
            .map_err(|e| MissionExperimentError::World(e.to_string()))?;
    }
    Ok(map.change_scores(f64::from(seconds)))
}

/// Runs the comparison; `progress` after each mission.
pub fn run(
    options: &MissionExperiment,
    progress: Progress<'_>,
) -> Result<MissionReproduction, MissionExperimentError> {
    let scenario = builtin()?;
    let inflated = inflate(
        &scenario.occupancy,
        scenario.file.robot_radius_m.unwrap_or(0.2),
        65,
    );
    let mut world = World::new(&inflated, &scenario.information, 0.25)
        .map_err(|e| MissionExperimentError::World(e.to_string()))?;
    let anchors: Vec<[f64; 2]> = scenario.file.anchors.iter().map(|a| a.at).collect();
    let model = RangingModel::from_spec(&anchors, &scenario.file.sensing)
        .map_err(|e| MissionExperimentError::World(e.to_string()))?;
    let meta = scenario.occupancy.meta;
    let region = GridRegion {
        origin: [meta.origin.x, meta.origin.y],
        resolution_m: meta.resolution,
        width: meta.width as usize,
        height: meta.height as usize,
    };
    let field = peb_field(&model, &region, &FimOptions::default())
        .map_err(|e| MissionExperimentError::World(e.to_string()))?;
    world.set_localizability(&field.peb);
    let params = GaParams::default();
    let mut change_world = world.clone();
    change_world.information = change_information(&scenario, 60)?;
    // Model II's block sums follow the information map.
    change_world.set_heuristic_compression(params.heuristic_compression);
    let peb_at = |p: [f64; 2]| -> f64 {
        world
            .cell_at(p[0], p[1])
            .map_or(f64::NAN, |c| f64::from(world.localizability[c as usize]))
    };
    let apf = ApfParams::indoor();
    let free: Vec<u32> = (0..world.cell_count() as u32)
        .filter(|&c| world.is_traversable(c))
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut sums = [[0.0f64; 4]; VARIANTS.len()];
    let mut per_mission: [Vec<MissionInformation>; VARIANTS.len()] = Default::default();
    for mission in 0..options.missions {
        let pick = |rng: &mut ChaCha8Rng| {
            let c = free[rng.random_range(0..free.len())];
            let (x, y) = world.center(c);
            [x, y]
        };
        let start = pick(&mut rng);
        let mut goal = pick(&mut rng);
        while distance(start, goal) < 8.0 {
            goal = pick(&mut rng);
        }
        let cancel = AtomicBool::new(false);
        let plan_on = |world: &World, model: PlannerModel, t_exec: f64, w_loc: f64| {
            let mut spec = PlanSpec::batch(
                start,
                goal,
                t_exec,
                model,
                options.generations,
                options.seed ^ mission as u64,
            );
            spec.params.w_loc = w_loc;
            plan(world, &spec, &cancel, |_, _| {})
                .map_err(|e| MissionExperimentError::Plan(e.to_string()))
        };
        let plan_with = |model, t_exec, w_loc| plan_on(&world, model, t_exec, w_loc);
        let shortest = plan_with(PlannerModel::Shortest, 86_400.0, 0.0)?;
        let budget = 2.0 * shortest.t_eta_s;
        let mut driving = scenario.clone();
        if let Some(robot) = driving.file.robots.first_mut() {
            robot.at = start;
        }
        let setup =
            Setup::new(&driving).map_err(|e| MissionExperimentError::Drive(e.to_string()))?;
        let step_s = driving.file.time.step_s;
        for (v, variant) in VARIANTS.iter().enumerate() {
            let outcome = match *variant {
                "static" => plan_with(PlannerModel::Model1, budget, 0.0)?,
                "peb_cost" => plan_with(PlannerModel::Model1, budget, options.w_loc)?,
                "change" => plan_on(&change_world, PlannerModel::Model1, budget, 0.0)?,
                _ => shortest.clone(),
            };
            let points = world.centers(&outcome.path);
            let waypoints = mission_waypoints(&points, 1.0);
            let robot = driving
                .file
                .robots
                .first()
                .map_or("robot".to_owned(), |r| r.name.clone());
            let episode = run_episode(
                &setup,
                &ApfParams {
                    max_steps: ((budget * 3.0) / step_s) as u64 + 100,
                    ..apf.clone()
                },
                PositionSource::Estimate,
                &[RobotMission { robot, waypoints }],
                options.seed ^ (mission as u64).wrapping_mul(0x9E37_79B9),
            )
            .map_err(|e| MissionExperimentError::Drive(e.to_string()))?;
            let Some(track) = episode.robots.first() else {
                continue;
            };
            let on_time = track.success && track.steps as f64 * step_s <= budget;
            let pebs: Vec<f64> = track
                .truth
                .iter()
                .map(|&p| peb_at(p))
                .filter(|p| p.is_finite())
                .collect();
            let peb = if pebs.is_empty() {
                0.0
            } else {
                pebs.iter().sum::<f64>() / pebs.len() as f64
            };
            let driven = gathered(&world, &params, &track.truth);
            let planned = outcome.metrics.distinct_information;
            sums[v][0] += driven;
            sums[v][1] += f64::from(u8::from(on_time));
            sums[v][2] += peb;
            sums[v][3] += planned;
            per_mission[v].push(MissionInformation {
                driven,
                planned,
                driven_over_planned: (planned > 0.0).then(|| driven / planned),
            });
        }
        progress(Done::of(
            "missions",
            "missions",
            mission + 1,
            options.missions,
        ));
    }
    let n = options.missions.max(1) as f64;
    Ok(MissionReproduction {
        missions: options.missions,
        seed: options.seed,
        variants: VARIANTS
            .iter()
            .zip(sums)
            .zip(per_mission)
            .map(|((variant, s), per_mission)| VariantResult {
                variant,
                information: s[0] / n,
                on_time_share: s[1] / n,
                peb_mean_m: s[2] / n,
                planned_information: s[3] / n,
                driven_over_planned_median: median(
                    per_mission
                        .iter()
                        .filter_map(|m| m.driven_over_planned)
                        .collect(),
                ),
                per_mission,
            })
            .collect(),
    })
}

/// The comparison as a terminal table.
pub fn table(r: &MissionReproduction) -> String {
    let mut out = format!(
        "the papers joined: {} seeded downtime missions in the built-in world (budget 2x the shortest ETA)\n",
        r.missions
    );
    out.push_str(&format!(
        "{:<10} {:>12} {:>12} {:>14} {:>12} {:>16}\n",
        "variant", "information", "on time", "mean PEB m", "planned I", "driven/planned"
    ));
    for v in &r.variants {
        let ratio = v
            .driven_over_planned_median
            .map_or_else(|| "-".to_owned(), |m| format!("{m:.3}"));
        out.push_str(&format!(
            "{:<10} {:>12.0} {:>11.0}% {:>14.3} {:>12.0} {:>16}\n",
            v.variant,
            v.information,
            v.on_time_share * 100.0,
            v.peb_mean_m,
            v.planned_information,
            ratio
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn the_median_of_odd_even_and_no_values() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(Vec::new()), None);
    }
}
