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

use crate::seen::{seen_world, SeenObstacles};

use super::events::{Now, WindowAction};
use super::state::{DowntimeWindow, Phase};
use super::straight;

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
