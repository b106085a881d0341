//! Planning around what the fleet has seen (roam's, not paper 000's). The map server's
//! `inflated` layer is the static map: a pallet left in an aisle is not in it, and a
//! planner on it alone sends a robot into that pallet again after every replan, until
//! its task is given up. A planner with `obstacles_layer` set (the mapper's `occupied_now`, ROS
//! occupancy 0..=100 on the map's grid) also blocks every cell within
//! `obstacle_inflation_m` of a cell that layer believes occupied
//! (≥ [`OBSTACLE_AT`]) where the static map has it free. Cells the static map has
//! blocked are left as they are, so walls are not inflated twice, and a cell nobody has
//! seen takes the static map's value in `occupied_now`, so unknown space adds nothing.
//!
//! A robot next to what it saw may stand inside the new inflation: the plan's start
//! moves to the nearest free cell ([`crate::plan`], `START_SNAP_M`).

use roam_proto::cells::Cells;
use roam_proto::map::Layer;
use roam_world::grid::{occupancy, Grid};

/// A cell believed occupied at least this much (0..=100) is an obstacle.
pub const OBSTACLE_AT: i8 = 50;
/// The most an obstacle is inflated, metres.
pub const MAX_OBSTACLE_INFLATION_M: f64 = 5.0;

/// The cells (indices into `inflated`) `seen` believes occupied where `inflated` has
/// them free: the obstacles the fleet saw that the static map does not have. `None` when
/// `seen` is not i8 cells on `inflated`'s grid. The mission executive checks its route
/// against the same cells (`roam_mission::window::SeenObstacles`).
pub fn seen_obstacle_cells(inflated: &Grid<i8>, seen: &Layer) -> Option<Vec<usize>> {
    let Cells::I8(belief) = &seen.cells else {
        return None;
    };
    if seen.meta != inflated.meta || belief.len() != inflated.cells.len() {
        return None;
    }
    Some(
        belief
            .iter()
            .zip(&inflated.cells)
            .enumerate()
            .filter(|(_, (&b, &static_cell))| b >= OBSTACLE_AT && static_cell == occupancy::FREE)
            .map(|(i, _)| i)
            .collect(),
    )
}

/// Blocks on `inflated` every free cell within `radius_m` of a cell `seen` believes
/// occupied where `inflated` has it free. Returns how many cells it blocked, or `None`
/// when `seen` is not i8 cells on `inflated`'s grid (then nothing changes).
pub fn block_seen(inflated: &mut Grid<i8>, seen: &Layer, radius_m: f64) -> Option<usize> {
    let obstacles = seen_obstacle_cells(inflated, seen)?;
    let (w, h) = (inflated.meta.width as i64, inflated.meta.height as i64);
    let r = (radius_m.max(0.0) / inflated.meta.resolution).ceil() as i64;
    let mut blocked = 0;
    for i in obstacles {
        let (cx, cy) = ((i as i64) % w, (i as i64) / w);
        for y in (cy - r).max(0)..=(cy + r).min(h - 1) {
            for x in (cx - r).max(0)..=(cx + r).min(w - 1) {
                if (x - cx).pow(2) + (y - cy).pow(2) > r * r {
                    continue;
                }
                let cell = &mut inflated.cells[(y * w + x) as usize];
                if *cell == occupancy::FREE {
                    *cell = occupancy::OCCUPIED;
                    blocked += 1;
                }
            }
        }
    }
    Some(blocked)
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};

    fn meta(w: u32, h: u32) -> GridMeta {
        GridMeta {
            width: w,
            height: h,
            resolution: 0.1,
            origin: Origin::default(),
        }
    }

    fn layer(meta: GridMeta, cells: Vec<i8>) -> Layer {
        Layer {
            name: "occupied_now".into(),
            version: 1,
            meta,
            derived_from: None,
            cells: Cells::I8(cells),
        }
    }

    #[test]
    fn a_seen_obstacle_blocks_a_disc_of_free_cells_and_walls_are_left_alone() {
        let m = meta(9, 9);
        let mut inflated = Grid::filled(m, occupancy::FREE);
        // A wall along x = 0.
        for y in 0..9 {
            inflated.cells[y * 9] = occupancy::OCCUPIED;
        }
        let mut belief = inflated.cells.clone();
        // A pallet seen at (4, 4); a cell at (7, 7) only 40% believed occupied.
        belief[4 * 9 + 4] = 100;
        belief[7 * 9 + 7] = 40;
        let seen = layer(m, belief);
        let blocked = block_seen(&mut inflated, &seen, 0.2).expect("fits");
        // A disc of radius 2 cells: 13 cells, none of them the wall's.
        assert_eq!(blocked, 13);
        assert_eq!(inflated.cells[4 * 9 + 6], occupancy::OCCUPIED);
        assert_eq!(
            inflated.cells[5 * 9 + 6],
            occupancy::FREE,
            "outside the disc"
        );
        assert_eq!(inflated.cells[7 * 9 + 7], occupancy::FREE, "below 50");
        // A wall in the belief (the static map's) adds nothing.
        let before = inflated.clone();
        let walls = layer(m, before.cells.iter().map(|&c| c.max(0)).collect());
        assert_eq!(block_seen(&mut inflated, &walls, 0.2), Some(0));
        assert_eq!(inflated, before);
    }

    #[test]
    fn a_layer_of_another_grid_changes_nothing() {
        let mut inflated = Grid::filled(meta(4, 4), occupancy::FREE);
        let other = layer(meta(5, 4), vec![100; 20]);
        assert_eq!(block_seen(&mut inflated, &other, 0.2), None);
        assert!(inflated.cells.iter().all(|&c| c == occupancy::FREE));
    }
}
