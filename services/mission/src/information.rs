//! The information a path gathers, measured as the planner measures it (paper 000 §III:
//! the distinct cells of the information map within the perception window of each cell
//! of the path), so planned, driven and shortest paths compare on one scale.

use roam_planner::metrics::path_metrics;
use roam_planner::params::GaParams;
use roam_planner::world::{Cell, World};

/// The information of the distinct cells seen from the grid cells the world points
/// `trajectory` pass through (consecutive repeats collapsed; points off the map skipped).
pub fn gathered(world: &World, params: &GaParams, trajectory: &[[f64; 2]]) -> f64 {
    let mut cells: Vec<Cell> = Vec::with_capacity(trajectory.len());
    for p in trajectory {
        if let Some(c) = world.cell_at(p[0], p[1]) {
            if cells.last() != Some(&c) {
                cells.push(c);
            }
        }
    }
    path_metrics(world, params, &cells).distinct_information
}

/// The scale a window's report measures its paths on (planned, driven, shortest): the
/// static information map and the planner's perception window, so the three compare
/// whatever map the planner planned on.
#[derive(Debug, Clone, Copy)]
pub struct InformationScale<'a> {
    pub world: &'a World,
    pub params: &'a GaParams,
}

impl InformationScale<'_> {
    /// [`gathered`] along `trajectory`.
    pub fn of(&self, trajectory: &[[f64; 2]]) -> f64 {
        gathered(self.world, self.params, trajectory)
    }
}
