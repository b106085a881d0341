//! Robots' starting places for the benchmarks that add many robots to the built-in
//! world (`sim`, `fleet`): free cells spread evenly over the map.

use roam_world::grid::cell_center;
use roam_world::scenario::load_or_builtin;

use crate::{setup, BenchError};

/// `robots` places on free cells of the built-in world, every `free / robots`-th of
/// them (with `away_from_walls`, only cells whose 8 neighbours are free too), and the
/// names of the world's own robots.
pub(crate) fn spread(
    robots: usize,
    away_from_walls: bool,
) -> Result<(Vec<[f64; 2]>, Vec<String>), BenchError> {
    let (_, scenario) = load_or_builtin(None).map_err(setup)?;
    let meta = scenario.occupancy.meta;
    let (width, height) = (meta.width as usize, meta.height as usize);
    let cells = &scenario.occupancy.cells;
    let free_at = |x: i64, y: i64| {
        x >= 0
            && y >= 0
            && (x as usize) < width
            && (y as usize) < height
            && cells[y as usize * width + x as usize] == 0
    };
    let free: Vec<usize> = (0..cells.len())
        .filter(|&i| {
            let (x, y) = ((i % width) as i64, (i / width) as i64);
            if !away_from_walls {
                return free_at(x, y);
            }
            (-1..=1).all(|dy| (-1..=1).all(|dx| free_at(x + dx, y + dy)))
        })
        .collect();
    if free.len() < robots {
        return Err(BenchError::Setup(format!(
            "the built-in world has only {} free cells",
            free.len()
        )));
    }
    let stride = free.len() / robots.max(1);
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
    Ok((places, own))
}
