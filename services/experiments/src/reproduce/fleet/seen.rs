//! The planner's grid around what the fleet has seen, as the live planner builds it
//! (`roam_planner::seen`, `obstacles_layer: occupied_now`): a pallet a robot saw in an
//! aisle is planned around by every robot after it, until the fleet sees it gone. The
//! fleet's belief (P(occupied now), kept on the planning grid) is laid onto the map's
//! 5 cm cells as the mapper's `occupied_now` layer (ROS occupancy 0..=100), the
//! planner's own [`block_seen`] blocks around each believed obstacle on the inflated
//! map, and the planning world is rebuilt from it at the planner's resolution, as the
//! planner service's map cache does on each new layer version.
//!
//! The live mapper sends its layers once a wall second ([`REFRESH_S`] at the demo's
//! 10×); the batch refreshes on that sim period, and rebuilds only when the set of
//! believed obstacles changed.

use std::sync::Arc;

use roam_mapper::belief::ros_occupancy;
use roam_mission::window::SeenObstacles;
use roam_planner::seen::{block_seen, OBSTACLE_AT};
use roam_planner::world::World;
use roam_proto::cells::Cells;
use roam_proto::map::Layer;
use roam_world::grid::occupancy;

use super::error::FleetError;
use super::world::{FleetWorld, PLANNING_RESOLUTION_M};

/// Sim seconds between two refreshes: the mapper's `publish_period_s` (1 s of wall
/// time) at `roam demo --fleet`'s rate of 10.
pub const REFRESH_S: f64 = 10.0;

/// How far around a believed obstacle the planner blocks, metres: the planner's
/// default `obstacle_inflation_m`, which `roam demo --fleet` runs with.
pub const OBSTACLE_INFLATION_M: f64 = 0.3;

/// The planning world the fleet plans on: the static one until the fleet believes an
/// obstacle the static map does not have.
#[derive(Debug, Default)]
pub struct SeenWorld {
    /// The coarse cells believed occupied where the static map is free, at the last
    /// refresh.
    obstacles: Vec<usize>,
    /// The world around them (`None`: there are none, plan on the static world).
    world: Option<Arc<World>>,
    next_refresh_s: f64,
    /// How many times the world was rebuilt.
    pub rebuilds: usize,
    /// The believed obstacles as the executives check their routes against them (the
    /// live executive's `obstacles_layer` follower makes the same set from the same
    /// layer), when the last refresh changed them.
    changed: Option<Arc<SeenObstacles>>,
}

impl SeenWorld {
    /// The world to plan on now.
    pub fn world<'a>(&'a self, fleet: &'a FleetWorld) -> &'a World {
        self.world.as_deref().unwrap_or(&fleet.planning)
    }

    /// Whether a refresh is due at `now_s`.
    pub fn due(&self, now_s: f64) -> bool {
        now_s >= self.next_refresh_s
    }

    /// The believed obstacles, if the last refresh changed them (taken once).
    pub fn take_changed(&mut self) -> Option<Arc<SeenObstacles>> {
        self.changed.take()
    }

    /// Takes the fleet's belief (P(occupied now) per coarse cell) at `now_s`, and
    /// rebuilds the world when the believed obstacles changed.
    pub fn refresh(
        &mut self,
        fleet: &FleetWorld,
        belief: &[f64],
        now_s: f64,
    ) -> Result<(), FleetError> {
        self.next_refresh_s = now_s + REFRESH_S;
        let scores = ros_occupancy(belief);
        let obstacles: Vec<usize> = scores
            .iter()
            .zip(&fleet.static_coarse.cells)
            .enumerate()
            .filter(|(_, (&p, &s))| p >= OBSTACLE_AT && s == occupancy::FREE)
            .map(|(i, _)| i)
            .collect();
        if obstacles == self.obstacles {
            return Ok(());
        }
        self.obstacles = obstacles;
        let occupied_now = occupied_now(fleet, &scores);
        self.world = if self.obstacles.is_empty() {
            None
        } else {
            Some(Arc::new(build(fleet, &occupied_now)?))
        };
        let set = SeenObstacles::of_layers(&fleet.inflated, &occupied_now, OBSTACLE_INFLATION_M)
            .ok_or_else(|| {
                FleetError::World("the fleet's belief is not on the map's grid".into())
            })?;
        self.changed = Some(Arc::new(set));
        self.rebuilds += 1;
        Ok(())
    }
}

/// The fleet's `occupied_now` on the coarse grid (`scores`), laid onto the map's cells
/// as the mapper publishes it.
fn occupied_now(fleet: &FleetWorld, scores: &[i8]) -> Layer {
    let meta = fleet.inflated.meta;
    let width = meta.width as usize;
    let cells: Vec<i8> = (0..fleet.inflated.cells.len())
        .map(|i| {
            let (x, y) = ((i % width) as i64, (i / width) as i64);
            fleet
                .coarse_index(x, y)
                .and_then(|c| scores.get(c))
                .map_or(occupancy::UNKNOWN, |&p| p)
        })
        .collect();
    Layer {
        name: "occupied_now".into(),
        version: 1,
        meta,
        derived_from: None,
        cells: Cells::I8(cells),
    }
}

/// The planning world around the fleet's `occupied_now`.
fn build(fleet: &FleetWorld, occupied_now: &Layer) -> Result<World, FleetError> {
    let mut inflated = fleet.inflated.clone();
    block_seen(&mut inflated, occupied_now, OBSTACLE_INFLATION_M)
        .ok_or_else(|| FleetError::World("the fleet's belief is not on the map's grid".into()))?;
    let mut world = World::at_resolution(
        &inflated,
        &fleet.information,
        fleet.planning.heuristic_compression,
        PLANNING_RESOLUTION_M,
    )
    .map_err(|e| FleetError::World(e.to_string()))?;
    world.set_localizability(&fleet.peb);
    Ok(world)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free planning cell in the middle of the warehouse's cross aisle (any free cell
    /// with free cells all round it does).
    fn open_cell(fleet: &FleetWorld) -> usize {
        let w = fleet.coarse.width as usize;
        let free = |i: usize| fleet.static_coarse.cells.get(i) == Some(&occupancy::FREE);
        (w + 1..fleet.static_coarse.cells.len() - w - 1)
            .find(|&i| {
                (0..9).all(|k| {
                    let (dx, dy) = (k % 3, k / 3);
                    free(i + dy * w + dx - w - 1)
                }) && fleet.planning.is_traversable(i as u32)
            })
            .expect("an open cell")
    }

    #[test]
    fn a_cell_the_fleet_believes_occupied_is_planned_around_until_seen_gone() {
        let fleet = FleetWorld::warehouse().expect("the warehouse");
        let cell = open_cell(&fleet);
        let mut seen = SeenWorld::default();
        let mut belief = vec![0.0; fleet.static_coarse.cells.len()];
        seen.refresh(&fleet, &belief, 0.0).expect("refresh");
        assert_eq!(seen.rebuilds, 0, "nothing believed: the static world");
        assert!(seen.world(&fleet).is_traversable(cell as u32));

        belief[cell] = 0.9;
        assert!(!seen.due(REFRESH_S / 2.0));
        assert!(seen.due(REFRESH_S));
        seen.refresh(&fleet, &belief, REFRESH_S).expect("refresh");
        assert_eq!(seen.rebuilds, 1);
        let around = seen.world(&fleet);
        assert!(
            !around.is_traversable(cell as u32),
            "the pallet's cell is blocked"
        );
        assert!(around.traversable_count() < fleet.planning.traversable_count());
        // The executives hear the new set once: the pallet's map cells, at its centre.
        let set = seen.take_changed().expect("a new set");
        let (x, y) = fleet.planning.center(cell as u32);
        assert!(!set.points.is_empty());
        assert!(set
            .points
            .iter()
            .all(|p| (p[0] - x).abs() <= 0.1 + 1e-9 && (p[1] - y).abs() <= 0.1 + 1e-9));
        assert_eq!(set.clearance_m, OBSTACLE_INFLATION_M);
        assert!(seen.take_changed().is_none());

        // The same belief again: no rebuild, nothing new to hear. Seen gone: the
        // static world again, and an empty set.
        seen.refresh(&fleet, &belief, 2.0 * REFRESH_S)
            .expect("refresh");
        assert_eq!(seen.rebuilds, 1);
        assert!(seen.take_changed().is_none());
        belief[cell] = 0.1;
        seen.refresh(&fleet, &belief, 3.0 * REFRESH_S)
            .expect("refresh");
        assert_eq!(seen.rebuilds, 2);
        assert!(seen.world(&fleet).is_traversable(cell as u32));
        assert_eq!(seen.take_changed().map(|s| s.points.len()), Some(0));
    }
}
