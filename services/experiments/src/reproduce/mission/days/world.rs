//! The day's world, built once and shared by every day and variant: the site's scenario
//! (the demo's day, [`roam_mission::tasks::DAY_SCENARIO`], or a user's map and day file,
//! [`roam_mission::site`]) as each service sees it.

use crate::closed_loop::setup::Setup;
use crate::closed_loop::stepper::Stepper;
use crate::closed_loop::PositionSource;
use roam_controller::params::ApfParams;
use roam_localization::field::{peb_field, GridRegion};
use roam_localization::{FimOptions, RangingModel};
use roam_planner::params::GaParams;
use roam_planner::world::World;
use roam_world::grid::Grid;
use roam_world::scenario::Scenario;

use super::error::DaysError;
use roam_mission::calibration::TimeModel;
use roam_mission::site::{inflated_map, Site, HEURISTIC_COMPRESSION};
use roam_mission::tasks::Task;

/// What every day shares.
#[derive(Debug, Clone)]
pub struct DayWorld {
    pub tasks: Vec<Task>,
    /// The robot the day drives (the scenario's first).
    pub robot: String,
    /// The controller's fields (obstacles, the anchors' PEB) and the scenario.
    pub setup: Setup,
    /// The sim's parameters as the sim service runs them: the scenario's, with its 3 m
    /// observation on (the mapper's input; it changes no trajectory, see
    /// [`Stepper::observing`]).
    pub sim_params: roam_sim::SimParams,
    /// The planner's grid: the inflated map, the static information map and
    /// localization's PEB field (for W_loc), as the planner service holds them.
    pub planning: World,
    /// Paper 000's parameters the information measure uses (the perception window).
    pub params: GaParams,
    /// The same grid with information 1 on every cell that the day's moving things
    /// (the cart) cover at some step and 0 elsewhere: the measure of change seen.
    pub changing: World,
    /// How many cells change during the day.
    pub changing_cells: usize,
    /// The sim's step, seconds.
    pub step_s: f64,
}

impl DayWorld {
    /// The site's day in its world (the demo's: [`Site::builtin_day`]).
    pub fn new(site: &Site) -> Result<DayWorld, DaysError> {
        let world = |e: &dyn std::fmt::Display| DaysError::World(e.to_string());
        let scenario: Scenario = site.scenario().map_err(|e| world(&e))?;
        let robot = site.robot.clone();
        if !scenario.file.robots.iter().any(|r| r.name == robot) {
            return Err(DaysError::World(format!(
                "the site's scenario has no robot {robot:?}"
            )));
        }
        let inflated = inflated_map(&scenario);
        let mut planning = World::new(&inflated, &scenario.information, HEURISTIC_COMPRESSION)
            .map_err(|e| world(&e))?;
        let anchors: Vec<[f64; 2]> = scenario.file.anchors.iter().map(|a| a.at).collect();
        let model =
            RangingModel::from_spec(&anchors, &scenario.file.sensing).map_err(|e| world(&e))?;
        let meta = scenario.occupancy.meta;
        let region = GridRegion {
            origin: [meta.origin.x, meta.origin.y],
            resolution_m: meta.resolution,
            width: meta.width as usize,
            height: meta.height as usize,
        };
        let field = peb_field(&model, &region, &FimOptions::default()).map_err(|e| world(&e))?;
        planning.set_localizability(&field.peb);
        let setup = Setup::new(&scenario).map_err(|e| world(&e))?;
        let sim_params = Stepper::observing(&setup);
        let tasks = site.tasks.clone();
        let start = scenario
            .file
            .robots
            .iter()
            .find(|r| r.name == robot)
            .map(|r| r.at);
        roam_mission::day_check::check_day(&tasks, &planning, TimeModel::table_i(), start)
            .map_err(|e| world(&e))?;
        let step_s = scenario.file.time.step_s;
        let day_s = tasks.last().map_or(0.0, |t| t.start_s + t.duration_s);
        let moving = changing_cells(&setup, sim_params, day_s, step_s)?;
        let changing_cells = moving.iter().filter(|&&c| c > 0).count();
        let changing = World::new(
            &inflated,
            &Grid {
                meta,
                cells: moving,
            },
            HEURISTIC_COMPRESSION,
        )
        .map_err(|e| world(&e))?;
        Ok(DayWorld {
            tasks,
            robot,
            setup,
            sim_params,
            planning,
            params: GaParams::default(),
            changing,
            changing_cells,
            step_s,
        })
    }
}

/// 1 on every cell that is occupied at some step of the day's first `day_s` seconds
/// and free on the static map (a block or walker came onto it), 0 elsewhere. The blocks
/// follow their scripts whatever the robots do, so this is every day's truth.
fn changing_cells(
    setup: &Setup,
    sim_params: roam_sim::SimParams,
    day_s: f64,
    step_s: f64,
) -> Result<Vec<u8>, DaysError> {
    let mut stepper = Stepper::new(
        setup,
        sim_params,
        &ApfParams::indoor(),
        PositionSource::Truth,
        0,
    )?;
    let still = &setup.scenario.occupancy.cells;
    let mut moving = vec![0u8; still.len()];
    let steps = (day_s / step_s).ceil() as u64 + 1;
    for _ in 0..steps {
        stepper.step()?;
        let now = stepper.sim().occupancy();
        for ((m, &was), &is) in moving.iter_mut().zip(still).zip(&now.cells) {
            if was == 0 && is != 0 {
                *m = 1;
            }
        }
    }
    Ok(moving)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_day_world_has_its_cart_a_peb_field_and_four_windows() {
        let w = DayWorld::new(&Site::builtin_day()).expect("world");
        assert_eq!(w.tasks.len(), 4);
        assert_eq!(w.robot, "robot");
        assert!(w.sim_params.sensing.observation_radius_m > 0.0);
        // A 0.8 m cart on four places 1.6 m apart along the docks: about 4 x 12 cells.
        assert!(
            (30..=80).contains(&w.changing_cells),
            "{} changing cells",
            w.changing_cells
        );
        let cart = w.changing.cell_at(6.2, -5.0).expect("on the map");
        assert_eq!(w.changing.information[cart as usize], 1);
        let office = w.changing.cell_at(-3.0, 3.0).expect("on the map");
        assert_eq!(w.changing.information[office as usize], 0);
        // The north-east room has no fix: its PEB is held at the cost's cap.
        let archive = w.planning.cell_at(8.0, 8.0).expect("on the map");
        let start = w.planning.cell_at(-8.0, -8.0).expect("on the map");
        assert!(w.planning.localizability[archive as usize] > 1.0);
        assert!(w.planning.localizability[start as usize] < 0.5);
    }
}
