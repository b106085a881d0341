//! The grid controller's planner (paper 004 §2): "a wave front starting from the goal
//! position is created and then a path is computed using hill climbing from the current
//! position to the goal. If the goal is blocked or hidden by walls, the planned path
//! takes the robot as close as possible to the goal."
//!
//! - The wavefront is a breadth-first search, 4-connected (the grid world's moves),
//!   over the cells not known occupied: unknown cells are passable (a robot exploring
//!   must plan through what it has not seen; the map is corrected as it goes). The
//!   robot's own cell is always passable.
//! - Hill climbing steps to the neighbour one wave closer, the first in the order +x,
//!   +y, −x, −y when several are.
//! - "As close as possible": when the goal is known occupied or not reachable from the
//!   robot, the target is the reachable cell nearest the goal in straight-line
//!   distance (ties: fewer steps from the robot, then the lower index), and the
//!   wavefront starts there.
//!
//! One call plans one step; the explorer calls it again after every update, so the
//! path follows the map as it changes. The search stops as soon as it reaches the
//! robot, and the buffers are reused (stamped, never cleared), so a step costs the
//! cells between robot and goal, not the whole map.

use std::collections::VecDeque;

use roam_world::grid::occupancy;
use serde::Serialize;

/// The 4-neighbourhood in the order hill climbing and random steps use.
pub const NEIGHBOURS: [(i64, i64); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

/// One planned step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct PlanStep {
    /// Where the robot heads: the goal, or the reachable cell nearest it.
    pub target: (u32, u32),
    /// The next cell, a 4-neighbour of the robot; `None` when the robot is at the target.
    pub next: Option<(u32, u32)>,
    /// Steps from the robot to the target.
    pub distance: u32,
    /// Whether the target is the goal itself.
    pub goal_reachable: bool,
}

/// The planner's reusable buffers (one map-sized array of distances and one of stamps).
#[derive(Debug, Clone, Default)]
pub struct Wavefront {
    distance: Vec<u32>,
    stamp: Vec<u32>,
    generation: u32,
    queue: VecDeque<u32>,
    /// The cells reached by the latest search, in order.
    reached: Vec<u32>,
}

struct Grid<'a> {
    obstacles: &'a [i8],
    width: u32,
    height: u32,
    robot: usize,
}

impl Grid<'_> {
    fn passable(&self, i: usize) -> bool {
        i == self.robot
            || self
                .obstacles
                .get(i)
                .is_some_and(|&v| v != occupancy::OCCUPIED)
    }

    fn index(&self, (x, y): (u32, u32)) -> usize {
        y as usize * self.width as usize + x as usize
    }

    fn cell(&self, i: usize) -> (u32, u32) {
        (
            (i % self.width as usize) as u32,
            (i / self.width as usize) as u32,
        )
    }

    fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (x, y) = self.cell(i);
        NEIGHBOURS.iter().filter_map(move |&(dx, dy)| {
            let (nx, ny) = (i64::from(x) + dx, i64::from(y) + dy);
            (nx >= 0 && ny >= 0 && nx < i64::from(self.width) && ny < i64::from(self.height))
                .then(|| ny as usize * self.width as usize + nx as usize)
        })
    }
}

impl Wavefront {
    pub fn new() -> Wavefront {
        Wavefront::default()
    }

    /// Plans one step from `robot` toward `goal` on a `width × height` obstacle map
    /// (ROS values, row-major). `None` when either cell is off the map or the map's
    /// size does not match.
    pub fn plan(
        &mut self,
        obstacles: &[i8],
        width: u32,
        height: u32,
        robot: (u32, u32),
        goal: (u32, u32),
    ) -> Option<PlanStep> {
        let n = width as usize * height as usize;
        let on = |(x, y): (u32, u32)| x < width && y < height;
        if obstacles.len() != n || !on(robot) || !on(goal) {
            return None;
        }
        let mut grid = Grid {
            obstacles,
            width,
            height,
            robot: 0,
        };
        grid.robot = grid.index(robot);
        if self.distance.len() != n {
            self.distance = vec![0; n];
            self.stamp = vec![0; n];
            self.generation = 0;
        }
        let (r, g) = (grid.robot, grid.index(goal));
        if grid.passable(g) && self.search(&grid, g, Some(r)) {
            return Some(self.climb(&grid, g, true));
        }
        // As close as possible: the reachable cell nearest the goal.
        self.search(&grid, r, None);
        let sq = |i: usize| {
            let (x, y) = grid.cell(i);
            let (dx, dy) = (
                i64::from(x) - i64::from(goal.0),
                i64::from(y) - i64::from(goal.1),
            );
            dx * dx + dy * dy
        };
        let target = self
            .reached
            .iter()
            .map(|&i| i as usize)
            .min_by_key(|&i| (sq(i), self.distance[i], i))
            .unwrap_or(r);
        self.search(&grid, target, Some(r));
        Some(self.climb(&grid, target, target == g))
    }

    fn known(&self, i: usize) -> Option<u32> {
        (self.stamp[i] == self.generation).then(|| self.distance[i])
    }

    /// Breadth-first from `source` over passable cells, until `stop` is reached (or the
    /// whole component). Returns whether `stop` was reached.
    fn search(&mut self, grid: &Grid<'_>, source: usize, stop: Option<usize>) -> bool {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.iter_mut().for_each(|s| *s = u32::MAX);
            self.generation = 1;
        }
        self.queue.clear();
        self.reached.clear();
        self.stamp[source] = self.generation;
        self.distance[source] = 0;
        self.queue.push_back(source as u32);
        self.reached.push(source as u32);
        if stop == Some(source) {
            return true;
        }
        while let Some(c) = self.queue.pop_front() {
            let c = c as usize;
            let d = self.distance[c] + 1;
            for nb in grid.neighbours(c) {
                if self.stamp[nb] == self.generation || !grid.passable(nb) {
                    continue;
                }
                self.stamp[nb] = self.generation;
                self.distance[nb] = d;
                self.queue.push_back(nb as u32);
                self.reached.push(nb as u32);
                if stop == Some(nb) {
                    return true;
                }
            }
        }
        false
    }

    /// The step from the robot down the wavefront last searched from `target`.
    fn climb(&self, grid: &Grid<'_>, target: usize, goal_reachable: bool) -> PlanStep {
        let r = grid.robot;
        let distance = self.known(r).unwrap_or(0);
        let next = (r != target)
            .then(|| {
                grid.neighbours(r)
                    .find(|&nb| self.known(nb) == Some(distance.wrapping_sub(1)))
            })
            .flatten()
            .map(|nb| grid.cell(nb));
        PlanStep {
            target: grid.cell(target),
            next,
            distance,
            goal_reachable,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map from rows written top (high y) to bottom: '#' occupied, '?' unknown,
    /// anything else free.
    fn map(rows: &[&str]) -> (Vec<i8>, u32, u32) {
        let (w, h) = (rows[0].len() as u32, rows.len() as u32);
        let mut cells = vec![0i8; (w * h) as usize];
        for (r, row) in rows.iter().enumerate() {
            let y = h as usize - 1 - r;
            for (x, ch) in row.chars().enumerate() {
                cells[y * w as usize + x] = match ch {
                    '#' => 100,
                    '?' => -1,
                    _ => 0,
                };
            }
        }
        (cells, w, h)
    }

    /// Follows the planner step by step; the path, robot cell first.
    fn walk(cells: &[i8], w: u32, h: u32, from: (u32, u32), goal: (u32, u32)) -> Vec<(u32, u32)> {
        let mut wave = Wavefront::new();
        let mut path = vec![from];
        let mut at = from;
        for _ in 0..(w * h) {
            let step = wave.plan(cells, w, h, at, goal).expect("plan");
            match step.next {
                None => break,
                Some(n) => {
                    let d = (i64::from(n.0) - i64::from(at.0)).abs()
                        + (i64::from(n.1) - i64::from(at.1)).abs();
                    assert_eq!(d, 1, "one 4-connected step");
                    assert_ne!(cells[(n.1 * w + n.0) as usize], 100, "never into a wall");
                    at = n;
                    path.push(at);
                }
            }
        }
        path
    }

    #[test]
    fn goes_around_a_wall_on_a_shortest_path() {
        let (cells, w, h) = map(&[
            ".....", //
            ".###.", //
            ".#...", //
            ".#.#.", //
            ".....", //
        ]);
        let path = walk(&cells, w, h, (0, 0), (4, 4));
        assert_eq!(path.len() - 1, 8, "Manhattan distance, no detour needed");
        assert_eq!(path.last(), Some(&(4, 4)));
        // From inside the wall's bend at (2, 1) to (0, 4): out at the bottom and round.
        let path = walk(&cells, w, h, (2, 1), (0, 4));
        assert_eq!(path.last(), Some(&(0, 4)));
        // Shortest: (2,1)→(2,0)→(1,0)→(0,0)→(0,1)→…→(0,4) = 7 steps.
        assert_eq!(path.len() - 1, 7);
        let mut wave = Wavefront::new();
        let first = wave.plan(&cells, w, h, (2, 1), (0, 4)).expect("plan");
        assert_eq!((first.distance, first.goal_reachable), (7, true));
    }

    #[test]
    fn a_blocked_or_unreachable_goal_means_as_close_as_possible() {
        let (cells, w, h) = map(&[
            "..#..", //
            "..#..", //
            "..#..", //
        ]);
        let mut wave = Wavefront::new();
        // The goal is a wall cell: the nearest reachable cell is beside it.
        let step = wave.plan(&cells, w, h, (0, 1), (2, 1)).expect("plan");
        assert_eq!(step.target, (1, 1));
        assert!(!step.goal_reachable);
        assert_eq!(step.next, Some((1, 1)));
        // The goal is behind the wall: the robot goes to the wall's near side.
        let path = walk(&cells, w, h, (0, 0), (4, 1));
        assert_eq!(path.last(), Some(&(1, 1)));
        // Already as close as possible: no step.
        let step = wave.plan(&cells, w, h, (1, 1), (4, 1)).expect("plan");
        assert_eq!((step.next, step.distance), (None, 0));
    }

    #[test]
    fn unknown_cells_are_passable_and_the_robot_cell_always() {
        let (mut cells, w, h) = map(&["???", "#?#"]);
        cells[(w + 1) as usize] = 100; // the robot's own cell (1, 1) marked occupied
        let path = walk(&cells, w, h, (1, 1), (1, 0));
        assert_eq!(path, vec![(1, 1), (1, 0)]);
        let mut wave = Wavefront::new();
        assert_eq!(wave.plan(&cells, w, h, (5, 0), (0, 0)), None);
        assert_eq!(wave.plan(&cells[1..], w, h, (0, 0), (0, 0)), None);
    }
}
