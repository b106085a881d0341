//! The first population's random walks from S (§II.A.1), with roam's choices (see the
//! module doc of [`crate::ga`]).

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::eta::step_time;
use crate::search::{descend_to_goal, descent_steps};
use crate::world::{Cell, MOVES};

use super::problem::{GaOptions, Problem};

/// A random walk from S (§II.A.1), see the module doc for roam's two choices.
pub(super) fn initial_walk(
    problem: &Problem<'_>,
    options: &GaOptions,
    rng: &mut ChaCha8Rng,
) -> Vec<Cell> {
    let world = problem.world;
    let manhattan = world.manhattan(problem.start, problem.goal).max(1);
    let map_cap = world.traversable_count().max(manhattan);
    let cap = if options.cap_walks_by_budget {
        let per_cell = world.meta.resolution * problem.params.v_lin;
        let budget_cells = if per_cell > 0.0 {
            (problem.t_exec / per_cell).ceil() as usize
        } else {
            map_cap
        };
        budget_cells.clamp(manhattan, map_cap)
    } else {
        map_cap
    };
    let max_cells = options.max_path_cells.max(1);
    let cap = cap.min(max_cells.saturating_sub(1).max(manhattan));
    let length = rng.random_range(manhattan..=cap);
    let mut walk = Vec::with_capacity((length + 1).min(max_cells));
    walk.push(problem.start);
    let mut cell = problem.start;
    let mut moves = [0 as Cell; 8];
    // Room for one more step: with it the walk, and the descent to the goal that
    // finishes it (a neighbour's descent is at most two steps longer), stays within
    // `max_cells`.
    let room = |walk: &Vec<Cell>, cell: Cell| {
        let descent = if options.complete_walks_to_goal {
            descent_steps(problem.goal_field, cell).saturating_add(2)
        } else {
            0
        };
        walk.len().saturating_add(1).saturating_add(descent) <= max_cells
    };
    // The round-trip rule (`walk_end_share`, see the module doc): neither the drawn
    // length nor G ends a walk before it has used this much of t_exec. 0 is the paper's
    // rule: 0 s are always used, so the walk stops at its length or at G.
    let floor = problem.params.walk_end_share * problem.t_exec;
    let mut t = 0.0;
    let mut prev_dir = None;
    let mut dirs = [0usize; 8];
    loop {
        let done = walk.len() >= length || cell == problem.goal;
        if (done && t >= floor) || !room(&walk, cell) {
            break;
        }
        let mut count = 0;
        for dir in 0..MOVES.len() {
            if let Some(next) = world.step(cell, dir) {
                moves[count] = next;
                dirs[count] = dir;
                count += 1;
            }
        }
        if count == 0 {
            break;
        }
        let pick = rng.random_range(0..count);
        cell = moves[pick];
        t += step_time(world, problem.params, prev_dir, dirs[pick]);
        prev_dir = Some(dirs[pick]);
        walk.push(cell);
    }
    if options.complete_walks_to_goal && cell != problem.goal {
        descend_to_goal(world, problem.goal_field, &mut walk);
    }
    // Only a walk that took no step can get here longer (its descent is the shortest
    // route, which fits the budget); cut it all the same, the bound is a promise.
    walk.truncate(max_cells);
    walk
}
