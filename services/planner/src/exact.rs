//! The best possible plan of a small instance, found exactly: what the planners' answers
//! are measured against (`roam bench planner --optimality`).
//!
//! **What is optimized** (the same on both sides of the comparison): the distinct
//! information of the path, Σ I_xy over the distinct cells in the perception windows of
//! its cells (Eq. 3's window; [`crate::metrics::path_metrics`]'s
//! `distinct_information`), over the paths from the start's cell to the goal's by legal
//! moves whose t_ETA (Eq. 2, turns counted, [`crate::eta::step_time`]) is within the
//! driving budget t_exec. This is what a robot learns on its way, and what the planners'
//! reports call information; it is not Model I's F_1 (which the greedy planner and the
//! GA maximize, with its novelty terms), so the gap it shows is roam's answer against
//! the best answer to the user's question, Model I's choices included. Paper 000 gives
//! no optimum; this is roam's measure.
//!
//! **How: depth-first branch and bound** over paths (a cell may be visited again).
//! - *Feasibility*: a move is tried only when the time so far, the move and a lower
//!   bound on the time from the next cell to the goal (Dijkstra over legal moves,
//!   turns left out) fit the budget.
//! - *Bound*: the information so far plus every unseen cell in the window of a cell the
//!   robot could still stand on (time so far + a lower bound to that cell + one from it
//!   to the goal within the budget). A branch whose bound does not beat the best path
//!   found is cut.
//! - *Dominance*: a state is (cell, last move, time, cells seen); one reached before at
//!   the same cell and heading, no later, having seen at least the same cells, is at
//!   least as good, so the branch is cut. At most [`MAX_STATES_PER_KEY`] states are kept
//!   per cell and heading.
//! - *Order*: moves that see the most new information first, and the planners' own
//!   answers as the first incumbent, so the bound bites early.
//!
//! The search stops after `node_limit` nodes; the answer then says it is not proven
//! (the best found, a lower bound on the optimum). Instances are limited to
//! [`MAX_EXACT_CELLS`] cells.

use std::collections::{BinaryHeap, HashMap};

use crate::eta::{path_eta, step_time};
use crate::params::GaParams;
use crate::world::{Cell, World};

/// The most cells an instance may have (the seen cells are a fixed-size bitset).
pub const MAX_EXACT_CELLS: usize = 256;

/// States kept per cell and heading for the dominance check.
pub const MAX_STATES_PER_KEY: usize = 256;

/// Words of the seen-cells bitset.
const WORDS: usize = MAX_EXACT_CELLS / 64;

type Seen = [u64; WORDS];

/// A search state's key: the cell and the move that reached it (the next move's turn
/// depends on it).
type StateKey = (Cell, Option<usize>);

/// Why an instance cannot be searched.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExactError {
    #[error("the instance has {cells} cells; the exact search takes at most {max}")]
    TooLarge { cells: usize, max: usize },
    #[error("the start or the goal is not a free cell of the map")]
    Blocked,
    #[error("no path from the start reaches the goal within the budget t_exec = {t_exec_s} s")]
    Infeasible { t_exec_s: f64 },
    #[error("the search stopped at its limit of {node_limit} nodes before it found any path to the goal; give an incumbent or a higher limit")]
    NodeLimit { node_limit: u64 },
}

/// The best path found and whether it is proven best.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactAnswer {
    pub path: Vec<Cell>,
    pub distinct_information: f64,
    pub t_eta_s: f64,
    /// The search ran to its end: no path within the budget sees more.
    pub proven: bool,
    /// Nodes (partial paths) the search expanded.
    pub nodes: u64,
}

/// Σ I over the distinct cells `path` perceives, and its t_ETA (Eq. 2) on `world`: the
/// objective and the budget check, as the search counts them.
pub fn score(world: &World, params: &GaParams, path: &[Cell]) -> (f64, f64) {
    let windows = windows(world, params);
    let mut seen = [0u64; WORDS];
    let mut value = 0u32;
    for &c in path {
        value += see(&mut seen, &windows[c as usize], &world.information);
    }
    (f64::from(value), path_eta(world, params, path))
}

/// The best path from `start` to `goal` within `t_exec_s` (module doc), searching at
/// most `node_limit` nodes; `incumbents` (paths from `start` to `goal`, e.g. the
/// planners' answers) start the search's best when they fit the budget.
pub fn best_path(
    world: &World,
    params: &GaParams,
    start: Cell,
    goal: Cell,
    t_exec_s: f64,
    incumbents: &[&[Cell]],
    node_limit: u64,
) -> Result<ExactAnswer, ExactError> {
    let cells = world.cell_count();
    if cells > MAX_EXACT_CELLS {
        return Err(ExactError::TooLarge {
            cells,
            max: MAX_EXACT_CELLS,
        });
    }
    if !world.is_traversable(start) || !world.is_traversable(goal) {
        return Err(ExactError::Blocked);
    }
    let lower = LowerBounds::new(world, params);
    if lower.time(start, goal) > t_exec_s {
        return Err(ExactError::Infeasible { t_exec_s });
    }
    let mut search = Search {
        world,
        params,
        goal,
        t_exec_s,
        windows: windows(world, params),
        lower,
        states: HashMap::new(),
        best: None,
        nodes: 0,
        node_limit,
        path: vec![start],
    };
    for path in incumbents {
        let fits = path.first() == Some(&start)
            && path.last() == Some(&goal)
            && path.windows(2).all(|w| world.is_legal_move(w[0], w[1]));
        let (value, t) = score(world, params, path);
        if fits && t <= t_exec_s && search.best.as_ref().is_none_or(|b| value > b.0) {
            search.best = Some((value, path.to_vec(), t));
        }
    }
    let mut seen = [0u64; WORDS];
    let value = see(
        &mut seen,
        &search.windows[start as usize],
        &world.information,
    );
    let finished = search.expand(start, None, 0.0, seen, value);
    let Some((value, path, t_eta_s)) = search.best else {
        return Err(if finished {
            ExactError::Infeasible { t_exec_s }
        } else {
            ExactError::NodeLimit { node_limit }
        });
    };
    Ok(ExactAnswer {
        path,
        distinct_information: value,
        t_eta_s,
        proven: finished,
        nodes: search.nodes,
    })
}

struct Search<'a> {
    world: &'a World,
    params: &'a GaParams,
    goal: Cell,
    t_exec_s: f64,
    windows: Vec<Seen>,
    lower: LowerBounds,
    /// Per (cell, last move): the states reached, as (time, cells seen).
    states: HashMap<StateKey, Vec<(f64, Seen)>>,
    /// The best path to the goal so far: its value, cells and t_ETA.
    best: Option<(f64, Vec<Cell>, f64)>,
    nodes: u64,
    node_limit: u64,
    path: Vec<Cell>,
}

/// Slack on time comparisons, seconds (sums of step times in another order).
const EPS_S: f64 = 1e-9;

impl Search<'_> {
    /// Searches below the path so far (ending at `cell` after move `dir`, at `time`,
    /// having seen `seen` worth `value`); `false` when the node limit cut it short.
    fn expand(
        &mut self,
        cell: Cell,
        dir: Option<usize>,
        time: f64,
        seen: Seen,
        value: u32,
    ) -> bool {
        self.nodes += 1;
        if self.nodes > self.node_limit {
            return false;
        }
        let value_f = f64::from(value);
        if cell == self.goal && self.best.as_ref().is_none_or(|b| value_f > b.0) {
            self.best = Some((value_f, self.path.clone(), time));
        }
        let best = self.best.as_ref().map_or(-1.0, |b| b.0);
        if f64::from(self.bound(cell, time, &seen, value)) <= best {
            return true;
        }
        if self.dominated(cell, dir, time, &seen) {
            return true;
        }
        // Each move with what it sees: the next state is made once, ordered, then
        // searched.
        let mut moves: Vec<(u32, usize, Cell, f64, Seen)> = (0..8)
            .filter_map(|d| {
                let next = self.world.step(cell, d)?;
                let t = time + step_time(self.world, self.params, dir, d);
                (t + self.lower.time(next, self.goal) <= self.t_exec_s + EPS_S).then(|| {
                    let mut after = seen;
                    let gain = see(
                        &mut after,
                        &self.windows[next as usize],
                        &self.world.information,
                    );
                    (gain, d, next, t, after)
                })
            })
            .collect();
        // Most new information first; ties by direction, so the order is fixed.
        moves.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        for (gain, d, next, t, after) in moves {
            self.path.push(next);
            let finished = self.expand(next, Some(d), t, after, value + gain);
            self.path.pop();
            if !finished {
                return false;
            }
        }
        true
    }

    /// The value so far plus every unseen cell in the window of a cell still in reach
    /// (to it and on to the goal within the budget).
    fn bound(&self, cell: Cell, time: f64, seen: &Seen, value: u32) -> u32 {
        let left = self.t_exec_s - time + EPS_S;
        let mut reach = [0u64; WORDS];
        for c in 0..self.world.cell_count() as Cell {
            if self.lower.time(cell, c) + self.lower.time(c, self.goal) <= left {
                for (r, w) in reach.iter_mut().zip(&self.windows[c as usize]) {
                    *r |= w;
                }
            }
        }
        let mut unseen = reach;
        for (u, s) in unseen.iter_mut().zip(seen) {
            *u &= !s;
        }
        value + weight(&unseen, &self.world.information)
    }

    /// Whether a state at least as good was reached at the same cell and heading;
    /// records this one when not.
    fn dominated(&mut self, cell: Cell, dir: Option<usize>, time: f64, seen: &Seen) -> bool {
        let states = self.states.entry((cell, dir)).or_default();
        let covers = |a: &Seen, b: &Seen| a.iter().zip(b).all(|(x, y)| x & y == *y);
        if states
            .iter()
            .any(|(t, s)| *t <= time + EPS_S && covers(s, seen))
        {
            return true;
        }
        states.retain(|(t, s)| !(time <= *t + EPS_S && covers(seen, s)));
        if states.len() < MAX_STATES_PER_KEY {
            states.push((time, *seen));
        }
        false
    }
}

/// Lower bounds on the driving time between any two cells: Dijkstra over legal moves
/// with each move's straight time, turns left out (so never above Eq. 2's time).
struct LowerBounds {
    cells: usize,
    times: Vec<f64>,
}

impl LowerBounds {
    fn new(world: &World, params: &GaParams) -> LowerBounds {
        let cells = world.cell_count();
        let mut times = vec![f64::INFINITY; cells * cells];
        for from in 0..cells {
            let row = &mut times[from * cells..(from + 1) * cells];
            if !world.is_traversable(from as Cell) {
                continue;
            }
            row[from] = 0.0;
            let mut heap = BinaryHeap::new();
            heap.push(Reverse(0.0, from as Cell));
            while let Some(Reverse(t, c)) = heap.pop() {
                if t > row[c as usize] {
                    continue;
                }
                for d in 0..8 {
                    let Some(next) = world.step(c, d) else {
                        continue;
                    };
                    let nt = t + step_time(world, params, Some(d), d);
                    if nt < row[next as usize] {
                        row[next as usize] = nt;
                        heap.push(Reverse(nt, next));
                    }
                }
            }
        }
        LowerBounds { cells, times }
    }

    fn time(&self, from: Cell, to: Cell) -> f64 {
        self.times[from as usize * self.cells + to as usize]
    }
}

/// A min-heap entry: time, then cell.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Reverse(f64, Cell);

impl Eq for Reverse {}

impl PartialOrd for Reverse {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Reverse {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

/// Each cell's perception window (Eq. 3) as a bitset of cells.
fn windows(world: &World, params: &GaParams) -> Vec<Seen> {
    let offsets = params.window();
    let (w, h) = (world.width() as i64, world.height() as i64);
    (0..world.cell_count())
        .map(|c| {
            let (x, y) = world.xy(c as Cell);
            let mut bits = [0u64; WORDS];
            for &(dx, dy) in &offsets {
                let (nx, ny) = (x as i64 + i64::from(dx), y as i64 + i64::from(dy));
                if (0..w).contains(&nx) && (0..h).contains(&ny) {
                    let i = (ny * w + nx) as usize;
                    bits[i / 64] |= 1 << (i % 64);
                }
            }
            bits
        })
        .collect()
}

/// Marks `window` seen; the information of the cells it newly saw.
fn see(seen: &mut Seen, window: &Seen, information: &[u8]) -> u32 {
    let mut new = [0u64; WORDS];
    for ((n, s), w) in new.iter_mut().zip(seen.iter_mut()).zip(window) {
        *n = w & !*s;
        *s |= w;
    }
    weight(&new, information)
}

/// Σ I over the cells of `bits`.
fn weight(bits: &Seen, information: &[u8]) -> u32 {
    let mut sum = 0;
    for (word_index, &word) in bits.iter().enumerate() {
        let mut rest = word;
        while rest != 0 {
            let bit = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            sum += u32::from(information[word_index * 64 + bit]);
        }
    }
    sum
}

#[cfg(test)]
mod tests;
