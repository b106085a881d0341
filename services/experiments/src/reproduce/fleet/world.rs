//! The warehouse as every service of the fleet sees it, built once and shared by every
//! variant: the scenario at its 5 cm, the shift, the planner's grid at its own
//! resolution (0.2 m, paper 000's) with localization's PEB field, and the mapper's grid,
//! which is the planner's: the fleet's change map, its news and its map now are kept
//! per planning cell, so that the planner reads them cell for cell.

use std::path::Path;

use roam_controller::params::ApfParams;
use roam_localization::field::{peb_field, GridRegion};
use roam_localization::{FimOptions, RangingModel};
use roam_mission::calibration::TimeModel;
use roam_mission::shift::{Shift, WAREHOUSE_SCENARIO, WAREHOUSE_SHIFT};
use roam_mission::site::{HEURISTIC_COMPRESSION, INFLATED_COST};
use roam_planner::params::GaParams;
use roam_planner::world::World;
use roam_proto::map::GridMeta;
use roam_world::grid::Grid;
use roam_world::layers::inflate;
use roam_world::scenario::{self, Scenario};
use roam_world::seed::splitmix64;
use roam_world::DEFAULT_MAX_CELLS;

use crate::closed_loop::episode::Setup;
use crate::closed_loop::stepper::Stepper;

use super::error::FleetError;
use super::patrol::Patrol;

/// The planner's (and the fleet mapper's) resolution, metres: paper 000's grid.
pub const PLANNING_RESOLUTION_M: f64 = 0.2;

/// Cells scored for the map error beside the cells objects can cover: a seeded sample
/// of the other free cells of this many.
pub const OTHER_CELLS_SCORED: usize = 2000;

/// What every variant of the fleet shares.
#[derive(Debug, Clone)]
pub struct FleetWorld {
    pub setup: Setup,
    /// The sim's parameters as the sim service runs them (observation on).
    pub sim_params: roam_sim::SimParams,
    pub shift: Shift,
    /// The planner's grid at [`PLANNING_RESOLUTION_M`]: the inflated map, the static
    /// information and the PEB field, as the planner service holds them.
    pub planning: World,
    /// The map's inflated occupancy and static information at its own resolution, and
    /// localization's PEB field on it: what the planning world is rebuilt from around
    /// what the fleet has seen ([`super::seen`]).
    pub inflated: Grid<i8>,
    pub information: Grid<u8>,
    pub peb: Vec<f32>,
    pub params: GaParams,
    /// The mapper's grid: the planning grid's cells.
    pub coarse: GridMeta,
    /// Map cells per planning cell along a side.
    pub factor: u32,
    /// The static map on the coarse grid (a cell occupied when any of its map cells
    /// is): the map now's prior for cells never seen.
    pub static_coarse: Grid<i8>,
    /// The coarse cells the map error is scored on: every cell an object of a change
    /// zone can cover, then a seeded sample of the others that are free.
    pub scored: Vec<usize>,
    /// How many of `scored` are cells objects can cover.
    pub zone_cells: usize,
    /// The operator's loop (`None`: the site gives none, and the `patrol` variant is
    /// refused).
    pub patrol: Option<Patrol>,
    pub step_s: f64,
}

fn world_error(e: &dyn std::fmt::Display) -> FleetError {
    FleetError::World(e.to_string())
}

impl FleetWorld {
    /// The built-in warehouse and its shift.
    pub fn warehouse() -> Result<FleetWorld, FleetError> {
        FleetWorld::new(WAREHOUSE_SCENARIO, WAREHOUSE_SHIFT)
    }

    /// The built-in warehouse with another shift's text; the patrol goes through every
    /// aisle unless the shift gives its own.
    pub fn new(scenario_text: &str, shift_text: &str) -> Result<FleetWorld, FleetError> {
        FleetWorld::build(Path::new("warehouse.yaml"), scenario_text, shift_text, true)
    }

    /// A user's site: a scenario file (its map, robots, anchors, zones and changes) and
    /// a shift file; the patrol is the shift's `patrol:` loop (the `patrol` variant is
    /// refused without one).
    pub fn from_files(scenario: &Path, shift: &Path) -> Result<FleetWorld, FleetError> {
        let read = |path: &Path| {
            std::fs::read_to_string(path)
                .map_err(|e| FleetError::World(format!("cannot read {}: {e}", path.display())))
        };
        FleetWorld::build(scenario, &read(scenario)?, &read(shift)?, false)
    }

    fn build(
        scenario_path: &Path,
        scenario_text: &str,
        shift_text: &str,
        aisle_patrol: bool,
    ) -> Result<FleetWorld, FleetError> {
        let scenario: Scenario = scenario::parse(scenario_path, scenario_text, DEFAULT_MAX_CELLS)
            .map_err(|e| world_error(&e))?;
        let shift = Shift::parse(shift_text, &scenario.file.places, &scenario.file.robots)
            .map_err(|e| world_error(&e))?;
        let meta = scenario.occupancy.meta;
        let inflated = inflate(
            &scenario.occupancy,
            scenario.file.robot_radius_m.unwrap_or(0.2),
            INFLATED_COST,
        );
        let mut planning = World::at_resolution(
            &inflated,
            &scenario.information,
            HEURISTIC_COMPRESSION,
            PLANNING_RESOLUTION_M,
        )
        .map_err(|e| world_error(&e))?;
        let anchors: Vec<[f64; 2]> = scenario.file.anchors.iter().map(|a| a.at).collect();
        let model = RangingModel::from_spec(&anchors, &scenario.file.sensing)
            .map_err(|e| world_error(&e))?;
        let region = GridRegion {
            origin: [meta.origin.x, meta.origin.y],
            resolution_m: meta.resolution,
            width: meta.width as usize,
            height: meta.height as usize,
        };
        let field =
            peb_field(&model, &region, &FimOptions::default()).map_err(|e| world_error(&e))?;
        planning.set_localizability(&field.peb);
        shift
            .check_on(&planning, TimeModel::table_i())
            .map_err(|e| world_error(&e))?;
        let coarse = planning.meta;
        let factor = (coarse.resolution / meta.resolution).round() as u32;
        let static_coarse = coarsen(&scenario.occupancy, coarse, factor);
        let setup = Setup::new(&scenario).map_err(|e| world_error(&e))?;
        let sim_params = Stepper::observing(&setup);
        let (scored, zone_cells) = scored_cells(&scenario, &static_coarse);
        let patrol = if !shift.patrol.is_empty() {
            Some(Patrol::through(&planning, shift.patrol.clone())?)
        } else if aisle_patrol {
            let localized = localized_world(&inflated, &scenario.information, &field.peb)?;
            Some(Patrol::through_aisles(&localized)?)
        } else {
            None
        };
        Ok(FleetWorld {
            step_s: scenario.file.time.step_s,
            setup,
            sim_params,
            shift,
            planning,
            inflated,
            information: scenario.information,
            peb: field.peb,
            params: GaParams::default(),
            coarse,
            factor,
            static_coarse,
            scored,
            zone_cells,
            patrol,
        })
    }

    /// What a map of the world now should hold, per coarse cell: the static map and
    /// every object that has landed (occupied when any of its map cells is). Carts and
    /// people are left out: they are gone before a map could send a robot around
    /// them, and no map predicts where a walker steps next.
    pub fn semi_static_truth(&self, landed: &[roam_proto::sim::ObjectTruth]) -> Vec<bool> {
        let mut truth: Vec<bool> = self.static_coarse.cells.iter().map(|&v| v >= 50).collect();
        for o in landed {
            let [x0, y0, x1, y1] = o.cells;
            for y in y0..=y1 {
                for x in x0..=x1 {
                    if let Some(i) = self.coarse_index(x, y) {
                        truth[i] = true;
                    }
                }
            }
        }
        truth
    }

    /// The coarse cell index of map cell (x, y).
    pub fn coarse_index(&self, x: i64, y: i64) -> Option<usize> {
        let f = i64::from(self.factor);
        let (cx, cy) = (x.div_euclid(f), y.div_euclid(f));
        (cx >= 0
            && cy >= 0
            && cx < i64::from(self.coarse.width)
            && cy < i64::from(self.coarse.height))
        .then(|| (cy * i64::from(self.coarse.width) + cx) as usize)
    }
}

/// `fine` on the coarse grid `coarse` (`factor` map cells a side): a coarse cell is
/// occupied when any of its map cells is, unknown when all are, free otherwise.
pub fn coarsen(fine: &Grid<i8>, coarse: GridMeta, factor: u32) -> Grid<i8> {
    let (cw, ch) = (coarse.width as usize, coarse.height as usize);
    let mut cells = vec![-1i8; cw * ch];
    let (fw, f) = (fine.meta.width as usize, factor as usize);
    for (i, &v) in fine.cells.iter().enumerate() {
        let (x, y) = (i % fw, i / fw);
        let c = (y / f) * cw + x / f;
        if let Some(slot) = cells.get_mut(c) {
            if v >= 50 {
                *slot = 100;
            } else if v >= 0 && *slot < 0 {
                *slot = 0;
            }
        }
    }
    Grid {
        meta: coarse,
        cells,
    }
}

/// The cells the map error is scored on (module doc of [`FleetWorld::scored`]).
fn scored_cells(scenario: &Scenario, static_coarse: &Grid<i8>) -> (Vec<usize>, usize) {
    let meta = static_coarse.meta;
    let (w, h) = (meta.width as usize, meta.height as usize);
    let mut in_zone = vec![false; w * h];
    for z in &scenario.file.changes {
        // Every cell a footprint centred in the rect covers.
        let [x0, y0, x1, y1] = z.rect;
        let [sx, sy] = z.size_m;
        let to = |v: f64, o: f64| ((v - o) / meta.resolution).floor() as i64;
        let (cx0, cy0) = (
            to(x0 - sx / 2.0, meta.origin.x),
            to(y0 - sy / 2.0, meta.origin.y),
        );
        let (cx1, cy1) = (
            to(x1 + sx / 2.0, meta.origin.x),
            to(y1 + sy / 2.0, meta.origin.y),
        );
        for y in cy0.max(0)..=cy1.min(h as i64 - 1) {
            for x in cx0.max(0)..=cx1.min(w as i64 - 1) {
                let i = y as usize * w + x as usize;
                in_zone[i] = static_coarse.cells[i] == 0;
            }
        }
    }
    let mut scored: Vec<usize> = (0..w * h).filter(|&i| in_zone[i]).collect();
    let zone_cells = scored.len();
    let others: Vec<usize> = (0..w * h)
        .filter(|&i| !in_zone[i] && static_coarse.cells[i] == 0)
        .collect();
    // A seeded, even spread over the other free cells.
    let mut state = 0x5C0_12ED;
    let mut picked = vec![false; others.len()];
    let want = OTHER_CELLS_SCORED.min(others.len());
    while scored.len() < zone_cells + want {
        state = splitmix64(state);
        let k = (state % others.len() as u64) as usize;
        if !picked[k] {
            picked[k] = true;
            scored.push(others[k]);
        }
    }
    (scored, zone_cells)
}

/// The planning world with every map cell where the robots do not localize blocked:
/// its PEB (localization's field, `peb` per map cell) above the fleet controller's
/// `max_peb_m`, where the controller would hold the robot. The operator's patrol keeps
/// to it ([`Patrol::through_aisles`]).
fn localized_world(
    inflated: &Grid<i8>,
    information: &Grid<u8>,
    peb: &[f32],
) -> Result<World, FleetError> {
    let max_peb_m = ApfParams::fleet().max_peb_m;
    let mut localized = inflated.clone();
    for (cell, &p) in localized.cells.iter_mut().zip(peb) {
        // A PEB that is not a number is no fix either.
        let fixed = f64::from(p) <= max_peb_m;
        if !fixed {
            *cell = roam_world::grid::occupancy::OCCUPIED;
        }
    }
    World::at_resolution(
        &localized,
        information,
        HEURISTIC_COMPRESSION,
        PLANNING_RESOLUTION_M,
    )
    .map_err(|e| world_error(&e))
}
