//! Where the fleet's robots start on the built-in world, and their missions.

use roam_proto::controller::Mission;
use roam_world::grid::cell_center;
use roam_world::scenario::load_or_builtin;

use crate::{setup, BenchError};

/// What the robots are: where each starts and its mission, the last one the joiner.
pub(super) struct Fleet {
    pub(super) places: Vec<[f64; 2]>,
}

impl Fleet {
    pub(super) fn name(k: usize) -> String {
        format!("fleet-{k}")
    }

    /// Robot `k`'s mission: to the robot half the fleet away and back.
    pub(super) fn mission(&self, k: usize) -> Mission {
        let n = self.places.len();
        Mission {
            after_step: None,
            robot: Fleet::name(k),
            id: format!("bench-{k}"),
            waypoints: vec![self.places[(k + n / 2) % n], self.places[k]],
            recovery: false,
        }
    }
}

/// `robots` places on free cells (every 8-neighbour free too) spread over the built-in
/// world, and its own robots' names (they leave the sim first).
pub(super) fn places(robots: usize) -> Result<(Fleet, Vec<String>), BenchError> {
    let (_, scenario) = load_or_builtin(None).map_err(setup)?;
    let meta = scenario.occupancy.meta;
    let width = meta.width as usize;
    let free: Vec<usize> = scenario
        .occupancy
        .cells
        .iter()
        .enumerate()
        .filter(|(i, &c)| {
            let (x, y) = (i % width, i / width);
            // Away from walls: every 8-neighbour free too.
            c == 0
                && (-1i64..=1).all(|dy| {
                    (-1i64..=1).all(|dx| {
                        let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                        nx >= 0
                            && ny >= 0
                            && (nx as usize) < width
                            && (ny as usize) < meta.height as usize
                            && scenario.occupancy.cells[ny as usize * width + nx as usize] == 0
                    })
                })
        })
        .map(|(i, _)| i)
        .collect();
    if free.len() < robots {
        return Err(BenchError::Setup(format!(
            "the built-in world has only {} free cells",
            free.len()
        )));
    }
    let stride = free.len() / robots;
    let places = (0..robots)
        .map(|k| {
            let i = free[k * stride];
            let (x, y) = cell_center(&meta, i % width, i / width);
            [x, y]
        })
        .collect();
    let own = scenario
        .file
        .robots
        .iter()
        .map(|r| r.name.clone())
        .collect();
    Ok((Fleet { places }, own))
}
