//! Shortest paths on the planning grid: the A* baseline (octile heuristic, the
//! `pathfinding` crate) and a distance field to the goal that the GA's initial walks use
//! to finish at the goal.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::world::{Cell, World, MOVES};

/// Move costs in integer units: 1000 per straight cell, 1414 per diagonal, so that A*
/// works on exact integers and the octile heuristic never overestimates. A path's cost
/// in these units, divided by [`STRAIGHT`], is never more than its length in cells
/// (1414 < 1000 · √2), so `v_lin · resolution · cost / STRAIGHT` is a lower bound of its
/// t_ETA (Eq. 2), which [`crate::seeds`] uses to rule out via-points before building paths.
pub const STRAIGHT: u32 = 1000;
const DIAGONAL: u32 = 1414;

fn move_cost(dir: usize) -> u32 {
    if dir % 2 == 1 {
        DIAGONAL
    } else {
        STRAIGHT
    }
}

/// The octile distance in cost units: admissible and consistent for 8-connected grids
/// with these costs.
fn octile(world: &World, a: Cell, b: Cell) -> u32 {
    let (ax, ay) = world.xy(a);
    let (bx, by) = world.xy(b);
    let (dx, dy) = (ax.abs_diff(bx) as u32, ay.abs_diff(by) as u32);
    let (lo, hi) = (dx.min(dy), dx.max(dy));
    STRAIGHT * (hi - lo) + DIAGONAL * lo
}

/// The shortest path by distance from `start` to `goal`, both included, or `None`
/// when the goal cannot be reached.
pub fn shortest_path(world: &World, start: Cell, goal: Cell) -> Option<Vec<Cell>> {
    let successors = |&c: &Cell| {
        (0..8)
            .filter_map(move |d| world.step(c, d).map(|n| (n, move_cost(d))))
            .collect::<Vec<_>>()
    };
    pathfinding::prelude::astar(
        &start,
        successors,
        |&c| octile(world, c, goal),
        |&c| c == goal,
    )
    .map(|(path, _)| path)
}

/// Cost to reach `goal` from every cell (cost units, `u32::MAX` where unreachable).
pub fn distance_field(world: &World, goal: Cell) -> Vec<u32> {
    let mut dist = vec![u32::MAX; world.cell_count()];
    if !world.is_traversable(goal) {
        return dist;
    }
    let mut heap = BinaryHeap::new();
    dist[goal as usize] = 0;
    heap.push(Reverse((0u32, goal)));
    while let Some(Reverse((d, cell))) = heap.pop() {
        if d > dist[cell as usize] {
            continue;
        }
        // Moves are symmetric (a legal step a→b implies b→a), so the field from the goal
        // is the cost to the goal.
        for dir in 0..MOVES.len() {
            if let Some(next) = world.step(cell, dir) {
                let nd = d + move_cost(dir);
                if nd < dist[next as usize] {
                    dist[next as usize] = nd;
                    heap.push(Reverse((nd, next)));
                }
            }
        }
    }
    dist
}

/// At most how many cells [`descend_to_goal`] appends from `cell`: every step costs at
/// least [`STRAIGHT`] and lowers the field by its cost. `usize::MAX` where the goal is
/// out of reach.
pub fn descent_steps(field: &[u32], cell: Cell) -> usize {
    match field.get(cell as usize) {
        Some(&d) if d != u32::MAX => (d / STRAIGHT) as usize,
        _ => usize::MAX,
    }
}

/// Appends to `path` the descent along `field` from its last cell to the goal (where
/// the field is 0). Returns false, leaving `path` as it was, if the last cell cannot
/// reach the goal.
pub fn descend_to_goal(world: &World, field: &[u32], path: &mut Vec<Cell>) -> bool {
    let Some(&last) = path.last() else {
        return false;
    };
    if field[last as usize] == u32::MAX {
        return false;
    }
    let original = path.len();
    let mut cell = last;
    while field[cell as usize] != 0 {
        let next = (0..8)
            .filter_map(|d| {
                world
                    .step(cell, d)
                    .map(|n| (field[n as usize].saturating_add(move_cost(d)), n))
            })
            .min();
        match next {
            Some((_, n)) if field[n as usize] < field[cell as usize] => {
                path.push(n);
                cell = n;
            }
            _ => {
                path.truncate(original);
                return false;
            }
        }
    }
    true
}
