//! What the fleet has seen that the static map lacks, as the mission executive checks
//! its routes against it: the cells the mapper's `occupied_now` believes occupied where
//! the static `inflated` map is free ([`SeenObstacles`]), and the planning world with
//! the cells near them blocked ([`seen_world`]), for the window's own fastest paths.
//! Built the same way live (`obstacles.rs`, from the layers) and in batch (the fleet's
//! `SeenWorld`), so both hear the same set. How the window uses it: `window/blocked.rs`.

use roam_planner::world::{Cell, World};

use crate::path::off_path_m;

/// The most obstacle points a set holds ([`SeenObstacles::of_layers`] keeps the first
/// ones): a map this full of news is better served by the stuck rule than by a check
/// that costs more than a plan.
pub const MAX_OBSTACLE_POINTS: usize = 200_000;

/// What the fleet believes occupied where the static map is free (the mapper's
/// `occupied_now` against the static `inflated` layer), as world points, and how close
/// a route may pass one.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SeenObstacles {
    /// The centres of the believed-occupied cells, metres.
    pub points: Vec<[f64; 2]>,
    /// A route passing closer than this to a point is blocked, metres: the planner's
    /// `obstacle_inflation_m` (what it blocks round each point).
    pub clearance_m: f64,
}

impl SeenObstacles {
    /// The cells the belief layer `seen` (the mapper's `occupied_now`) has occupied
    /// where the static `inflated` map has them free, as the planner finds them
    /// (`roam_planner::seen::seen_obstacle_cells`), at most [`MAX_OBSTACLE_POINTS`].
    /// `None` when `seen` is not on `inflated`'s grid.
    pub fn of_layers(
        inflated: &roam_world::grid::Grid<i8>,
        seen: &roam_proto::map::Layer,
        clearance_m: f64,
    ) -> Option<SeenObstacles> {
        let cells = roam_planner::seen::seen_obstacle_cells(inflated, seen)?;
        let meta = &inflated.meta;
        let w = meta.width as usize;
        let points = cells
            .into_iter()
            .take(MAX_OBSTACLE_POINTS)
            .map(|i| {
                let (x, y) = roam_world::grid::cell_center(meta, i % w, i / w);
                [x, y]
            })
            .collect();
        Some(SeenObstacles {
            points,
            clearance_m,
        })
    }

    /// Whether the polyline `route` passes within the clearance of a point.
    pub fn blocks(&self, route: &[[f64; 2]]) -> bool {
        let r = self.clearance_m;
        if route.is_empty() || self.points.is_empty() || r.is_nan() || r < 0.0 {
            return false;
        }
        // Only points in the route's box, grown by the clearance, can be near it.
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in route {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k] - r);
                hi[k] = hi[k].max(p[k] + r);
            }
        }
        self.points
            .iter()
            .filter(|p| (0..2).all(|k| p[k] >= lo[k] && p[k] <= hi[k]))
            .any(|&p| off_path_m(p, route) < r)
    }
}

/// `world` with every cell whose centre is within the clearance of an obstacle point
/// blocked (and the cell each point is in); `None` when there are no points.
pub fn seen_world(world: &World, obstacles: &SeenObstacles) -> Option<World> {
    if obstacles.points.is_empty() {
        return None;
    }
    let r = obstacles.clearance_m.max(0.0);
    let res = world.meta.resolution;
    let k = (r / res).ceil() as i64 + 1;
    let (w, h) = (world.width() as i64, world.height() as i64);
    let mut cells: Vec<Cell> = Vec::new();
    for p in &obstacles.points {
        let Some(at) = world.cell_at(p[0], p[1]) else {
            continue;
        };
        cells.push(at);
        let (x0, y0) = world.xy(at);
        for y in (y0 as i64 - k).max(0)..=(y0 as i64 + k).min(h - 1) {
            for x in (x0 as i64 - k).max(0)..=(x0 as i64 + k).min(w - 1) {
                let cell = world.cell(x as usize, y as usize);
                let (cx, cy) = world.center(cell);
                if (cx - p[0]).hypot(cy - p[1]) <= r {
                    cells.push(cell);
                }
            }
        }
    }
    cells.sort_unstable();
    cells.dedup();
    Some(world.with_blocked(&cells))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_route_is_blocked_only_where_it_passes_within_the_clearance() {
        let route = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]];
        let seen = |p: [f64; 2]| SeenObstacles {
            points: vec![p],
            clearance_m: 0.4,
        };
        assert!(seen([5.0, 0.3]).blocks(&route), "beside the first leg");
        assert!(seen([10.3, 5.0]).blocks(&route), "beside the second leg");
        assert!(!seen([5.0, 0.5]).blocks(&route), "just clear");
        assert!(!seen([5.0, 5.0]).blocks(&route), "inside the corner, far");
        assert!(seen([0.0, 0.0]).blocks(&[[0.0, 0.1]]), "a one-point route");
        assert!(!seen([5.0, 0.0]).blocks(&[]));
        assert!(!SeenObstacles::default().blocks(&route));
        let nan = SeenObstacles {
            points: vec![[5.0, 0.0]],
            clearance_m: f64::NAN,
        };
        assert!(!nan.blocks(&route));
    }

    #[test]
    fn the_obstacles_are_the_cells_believed_occupied_where_the_static_map_is_free() {
        use roam_proto::cells::Cells;
        use roam_proto::map::{GridMeta, Layer, Origin};
        use roam_world::grid::Grid;
        let meta = GridMeta {
            width: 4,
            height: 2,
            resolution: 0.5,
            origin: Origin::default(),
        };
        let mut inflated = Grid::filled(meta, 0i8);
        inflated.cells[3] = 100; // a wall, believed occupied too: not news
        let mut belief = vec![0i8; 8];
        belief[3] = 100;
        belief[6] = 90; // (2, 1): a pallet
        belief[1] = 20; // believed free enough
        let seen = Layer {
            name: "occupied_now".into(),
            version: 1,
            meta,
            derived_from: None,
            cells: Cells::I8(belief),
        };
        let obstacles = SeenObstacles::of_layers(&inflated, &seen, 0.3).expect("same grid");
        assert_eq!(obstacles.points, vec![[1.25, 0.75]]);
        assert_eq!(obstacles.clearance_m, 0.3);
        let other = Grid::filled(GridMeta { width: 2, ..meta }, 0i8);
        assert_eq!(SeenObstacles::of_layers(&other, &seen, 0.3), None);
    }
}
