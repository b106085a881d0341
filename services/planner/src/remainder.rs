//! A replan's warm start: the route the robot is driving ([`PlanRequest::seed_route`],
//! world metres) as a path on the planning grid, so that the GA starts from it.
//!
//! roam's, not paper 000's (the paper plans once, from the start). A replan from
//! scratch has nothing close to the route the robot is already driving in its first
//! population; the remainder of that route is a good path to the same task by
//! construction, so the GA's first population holds it
//! (beside the shortest path and the via-point seeds) and the ranking ([`crate::best`])
//! returns it when nothing fitter is found. The answer is never below driving on.
//!
//! The route's points are taken to the planning cells they fall in; consecutive equal
//! cells merge; a step that is not one legal move (a corner cut at the coarser grid, a
//! gap) is joined through one cell a legal move from both ends, when there is one. The route must
//! then run from the start's cell to the goal's: the start and the goal are joined to
//! its ends the same way.
//!
//! **A route the map now blocks is repaired, not dropped.** A map-change replan (a
//! pallet seen on the route ahead, `roam_planner::seen`) is asked with the route the
//! robot drives, and the planner's map blocks part of it: each blocked stretch is cut
//! out and its ends joined by the shortest way round (A*, `search::shortest_path`), at
//! most [`MAX_REPAIRS`] stretches a route. The rest of the route (the part the robot was
//! going to drive, which the plan was chosen for) stays the seed; a plan from scratch
//! would throw it away for a detour at the GA's mercy.
//!
//! A route that cannot be made a path this way, or that is
//! longer than the plan's chromosomes may be, is not used, and the reply says so
//! ([`roam_proto::planner::Plan::seed_route_used`]): a hint, never a reason to refuse.
//!
//! [`PlanRequest::seed_route`]: roam_proto::planner::PlanRequest::seed_route

use crate::search::shortest_path;
use crate::world::{Cell, World};

/// The most points a seed route may have ([`roam_proto::planner::MAX_SEED_ROUTE_POINTS`]).
pub use roam_proto::planner::MAX_SEED_ROUTE_POINTS;

/// Why a seed route was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum RemainderError {
    #[error("a point of the seed route is off the map")]
    OffMap,
    #[error("the seed route crosses cells that are not traversable on the planning grid, with no way round them (or in more than {MAX_REPAIRS} places)")]
    Blocked,
    #[error("two consecutive points of the seed route are not joined by one or two legal moves")]
    Gap,
    #[error("the seed route is longer than the plan's chromosomes may be ({max} cells)")]
    TooLong { max: usize },
    #[error("the plan has no population to seed (model shortest, or a budget only the fastest path fits)")]
    NoPopulation,
}

/// The most blocked stretches a seed route may have repaired ([`route_cells`]): each
/// costs a search, and a route blocked in more places than this is no longer the route
/// the robot was driving.
pub const MAX_REPAIRS: usize = 8;

/// `route` as a path on `world`'s cells from `start` to `goal` (module doc).
pub fn route_cells(
    world: &World,
    route: &[[f64; 2]],
    start: Cell,
    goal: Cell,
    max_cells: usize,
) -> Result<Vec<Cell>, RemainderError> {
    let mut path: Vec<Cell> = vec![start];
    let mut repairs = 0;
    // Inside a stretch the map blocks: its cells are skipped, and the next free cell is
    // joined by the shortest way round.
    let mut blocked = false;
    let cells = route.iter().map(|p| world.cell_at(p[0], p[1]));
    for cell in cells.chain(std::iter::once(Some(goal))) {
        let cell = cell.ok_or(RemainderError::OffMap)?;
        if !world.is_traversable(cell) {
            blocked = true;
            continue;
        }
        let last = *path.last().unwrap_or(&start);
        if cell == last {
            blocked = false;
            continue;
        }
        if blocked {
            repairs += 1;
            if repairs > MAX_REPAIRS {
                return Err(RemainderError::Blocked);
            }
            let round = shortest_path(world, last, cell).ok_or(RemainderError::Blocked)?;
            path.extend_from_slice(&round[1..]);
            blocked = false;
        } else {
            if !world.is_legal_move(last, cell) {
                path.push(world.via(last, cell).ok_or(RemainderError::Gap)?);
            }
            path.push(cell);
        }
        if path.len() > max_cells {
            return Err(RemainderError::TooLong { max: max_cells });
        }
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::Grid;

    /// A `side`² world at 0.2 m, free but for the `blocked` cells.
    fn test_world(side: u32, _height: u32, blocked: &[(usize, usize)]) -> World {
        let meta = GridMeta {
            width: side,
            height: side,
            resolution: 0.2,
            origin: Origin::default(),
        };
        let mut inflated = Grid::filled(meta, 0i8);
        for &(x, y) in blocked {
            inflated.cells[y * side as usize + x] = 100;
        }
        World::new(&inflated, &Grid::filled(meta, 50u8), 0.25).expect("world")
    }

    #[test]
    fn a_route_along_free_cells_becomes_the_path_from_start_to_goal() {
        let world = test_world(10, 10, &[]);
        let start = world.cell(1, 1);
        let goal = world.cell(6, 1);
        // Points at the cells' centres from (1, 1) to (6, 1), with a repeat and a jump
        // of two cells that a corner joins.
        let route: Vec<[f64; 2]> = [(1, 1), (2, 1), (2, 1), (4, 1), (5, 1)]
            .iter()
            .map(|&(x, y)| {
                let (cx, cy) = world.center(world.cell(x, y));
                [cx, cy]
            })
            .collect();
        let path = route_cells(&world, &route, start, goal, 100).expect("joined");
        let expected: Vec<Cell> = (1..=6).map(|x| world.cell(x, 1)).collect();
        assert_eq!(path, expected);
        assert!(path.windows(2).all(|w| world.is_legal_move(w[0], w[1])));
    }

    #[test]
    fn a_route_that_cannot_be_joined_or_is_too_long_is_not_used() {
        let world = test_world(10, 10, &[(3, 1)]);
        let start = world.cell(1, 1);
        let goal = world.cell(6, 1);
        let at = |x: usize, y: usize| {
            let (cx, cy) = world.center(world.cell(x, y));
            [cx, cy]
        };
        // A wall across the whole map: no way round.
        let walled: Vec<(usize, usize)> = (0..10).map(|y| (3, y)).collect();
        let world_walled = test_world(10, 10, &walled);
        assert_eq!(
            route_cells(&world_walled, &[at(1, 1), at(3, 1)], start, goal, 100),
            Err(RemainderError::Blocked)
        );
        assert_eq!(
            route_cells(&world, &[at(1, 1), at(1, 8)], start, goal, 100),
            Err(RemainderError::Gap)
        );
        assert_eq!(
            route_cells(&world, &[[1e6, 0.0]], start, goal, 100),
            Err(RemainderError::OffMap)
        );
        assert_eq!(
            route_cells(&world, &[at(1, 1), at(1, 2), at(1, 3)], start, goal, 2),
            Err(RemainderError::TooLong { max: 2 })
        );
    }

    #[test]
    fn a_route_the_map_now_blocks_is_repaired_round_the_block() {
        // An obstacle across cells (3..=5, 0..=2) on the straight route along y = 1.
        let obstacle: Vec<(usize, usize)> =
            (3..=5).flat_map(|x| (0..=2).map(move |y| (x, y))).collect();
        let world = test_world(10, 10, &obstacle);
        let (start, goal) = (world.cell(1, 1), world.cell(8, 1));
        let route: Vec<[f64; 2]> = (1..=8)
            .map(|x| {
                let (cx, cy) = world.center(world.cell(x, 1));
                [cx, cy]
            })
            .collect();
        let path = route_cells(&world, &route, start, goal, 100).expect("repaired");
        assert_eq!(path.first(), Some(&start));
        assert_eq!(path.last(), Some(&goal));
        assert!(path.iter().all(|&c| world.is_traversable(c)));
        assert!(path.windows(2).all(|w| world.is_legal_move(w[0], w[1])));
        // The free parts of the route are kept: it leaves along y = 1 and comes back
        // to it after the obstacle.
        assert_eq!(path[1], world.cell(2, 1));
        assert!(path.contains(&world.cell(6, 1)) && path.contains(&world.cell(7, 1)));
        // Round, not through: the detour passes above the obstacle (y = 3).
        assert!(path.iter().any(|&c| world.xy(c).1 == 3));
    }

    #[test]
    fn a_route_blocked_in_more_places_than_the_limit_is_not_used() {
        // Single blocked cells on y = 1 at every other x, each with a way round.
        let blocks: Vec<(usize, usize)> = (0..=MAX_REPAIRS).map(|i| (2 + 2 * i, 1)).collect();
        let side = 2 * MAX_REPAIRS as u32 + 6;
        let world = test_world(side, side, &blocks);
        let last = side as usize - 2;
        let (start, goal) = (world.cell(1, 1), world.cell(last, 1));
        let route: Vec<[f64; 2]> = (1..=last)
            .map(|x| {
                let (cx, cy) = world.center(world.cell(x, 1));
                [cx, cy]
            })
            .collect();
        assert_eq!(
            route_cells(&world, &route, start, goal, 1000),
            Err(RemainderError::Blocked)
        );
        // One block fewer is repaired.
        let fewer = test_world(side, side, &blocks[..MAX_REPAIRS]);
        let path = route_cells(&fewer, &route, start, goal, 1000);
        assert!(path.is_ok(), "{path:?}");
    }
}
