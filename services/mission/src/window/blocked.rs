//! The route ahead blocked by what the fleet has seen: a pallet left in an aisle the
//! robot's route crosses. roam's, not the papers' (paper 000 plans on a static map).
//!
//! The planner already plans around what the fleet believes occupied
//! (`roam_planner::seen`, `obstacles_layer`), but only for plans asked after the fleet
//! saw it: a robot sent on a route before a pallet landed on it drives on until the
//! controller finds it stuck, then asks the shortest way, and its window's curiosity is
//! spent on the wait. The window instead hears each new set of believed obstacles
//! ([`WindowEvent::MapChanged`](super::WindowEvent::MapChanged)) and checks the route
//! left against it: when the route passes within the obstacles' clearance, it replans
//! at once (`map_changed`), as a slack replan does, from where the robot will be when
//! the plan comes and seeded with the route left, which the planner repairs round the
//! block (`roam_planner::remainder`).
//!
//! The window's own fastest paths (set off, the last safe moment, late, no planner)
//! go round the cells within the clearance of the obstacles last heard.
//!
//! A set heard while a plan is in flight (or the robot is recovering) is checked once
//! that is over, on the next tick. Only the current route is checked, and only when a
//! set arrives: a route the planner sent after the set was planned around it.

use roam_planner::world::{Cell, World};

use crate::path::off_path_m;

use super::events::{Now, WindowAction};
use super::state::{DowntimeWindow, Phase};
use super::straight;

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
        let near: Vec<[f64; 2]> = self
            .points
            .iter()
            .filter(|p| (0..2).all(|k| p[k] >= lo[k] && p[k] <= hi[k]))
            .copied()
            .collect();
        if near.is_empty() {
            return false;
        }
        near.iter().any(|&p| off_path_m(p, route) < r)
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

impl DowntimeWindow<'_> {
    /// A new set of believed obstacles: kept, and the route left checked against it.
    pub(super) fn on_map_changed(
        &mut self,
        obstacles: std::sync::Arc<SeenObstacles>,
        now: Now,
    ) -> Vec<WindowAction> {
        self.seen_world = seen_world(self.setup.scale.world, &obstacles);
        self.obstacles = Some(obstacles);
        self.obstacles_unchecked = true;
        self.check_route_clear(now)
    }

    /// The route left against the last set heard, once per set, when no plan is in
    /// flight and the robot is not recovering (module doc).
    pub(super) fn check_route_clear(&mut self, now: Now) -> Vec<WindowAction> {
        if !self.obstacles_unchecked {
            return Vec::new();
        }
        let Phase::Driving(drive) = &mut self.phase else {
            // Not driving: the next route is planned on the planner's map.
            self.obstacles_unchecked = false;
            return Vec::new();
        };
        if self.drive_ask.is_some() || drive.recovering {
            return Vec::new();
        }
        self.obstacles_unchecked = false;
        let Some(obstacles) = &self.obstacles else {
            return Vec::new();
        };
        if !obstacles.blocks(&straight::route_left(&drive.path, self.here)) {
            return Vec::new();
        }
        let decision = drive.watch.on_route_blocked(drive.route_curious);
        self.decide(decision, now)
    }
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
