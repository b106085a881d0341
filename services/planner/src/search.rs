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

/// A cost that orders by [`f64::total_cmp`], for the heaps of the time searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Seconds(pub(crate) f64);

impl Eq for Seconds {}

impl PartialOrd for Seconds {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Seconds {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The best time found to each state and the heading it came from, for the searches
/// over (cell, heading): dense below [`DENSE_STATES`] states, a hash map above (a
/// 1.7-million-cell map has 15 million states, of which A* touches a few).
#[derive(Debug)]
pub(crate) enum StateStore {
    Dense { time: Vec<f64>, from: Vec<u8> },
    Sparse(std::collections::HashMap<u64, (f64, u8)>),
}

/// Above this many states a search keeps its labels in a hash map (9 bytes a state
/// dense: 36 MB here).
pub(crate) const DENSE_STATES: u64 = 4_000_000;

/// The `from` of a state nobody has reached.
pub(crate) const UNREACHED: u8 = u8::MAX;

impl StateStore {
    pub(crate) fn new(states: u64) -> Self {
        if states <= DENSE_STATES {
            StateStore::Dense {
                time: vec![f64::INFINITY; states as usize],
                from: vec![UNREACHED; states as usize],
            }
        } else {
            StateStore::Sparse(std::collections::HashMap::new())
        }
    }

    pub(crate) fn time(&self, state: u64) -> f64 {
        match self {
            StateStore::Dense { time, .. } => time[state as usize],
            StateStore::Sparse(map) => map.get(&state).map_or(f64::INFINITY, |e| e.0),
        }
    }

    pub(crate) fn from(&self, state: u64) -> u8 {
        match self {
            StateStore::Dense { from, .. } => from[state as usize],
            StateStore::Sparse(map) => map.get(&state).map_or(UNREACHED, |e| e.1),
        }
    }

    pub(crate) fn set(&mut self, state: u64, t: f64, from_heading: u8) {
        match self {
            StateStore::Dense { time, from } => {
                time[state as usize] = t;
                from[state as usize] = from_heading;
            }
            StateStore::Sparse(map) => {
                map.insert(state, (t, from_heading));
            }
        }
    }
}

/// The heading index of "no move yet" (the start: Eq. 2 charges its first move no turn).
pub(crate) const NO_HEADING: usize = 8;

/// The fastest path from `start` to `goal` by paper 000's Eq. 2 (`v_lin · Σd +
/// v_ang · Σθ`: distance *and* turns), both included, or `None` when the goal cannot
/// be reached.
///
/// The distance-shortest path ([`shortest_path`]) ignores turns, so on a grid it often
/// zigzags where one turn would do: on a warehouse map it was 95.4 s where a 90.7 s path
/// exists, and a budget between the two was refused (issue 16). This is A* over
/// (cell, heading of the move that entered it), 9 headings with "none yet" at the
/// start; a move costs [`crate::eta::step_time`] after the previous heading, so a
/// path's cost is its t_ETA summed in the same order as [`crate::eta::path_eta`] sums
/// it, bit for bit. The heuristic is the octile distance at v_lin (turns cost ≥ 0), so
/// the path is optimal. Ties break on the state index: the same input gives the same
/// path.
pub fn fastest_path(
    world: &World,
    params: &crate::params::GaParams,
    start: Cell,
    goal: Cell,
) -> Option<Vec<Cell>> {
    if !world.is_traversable(start) || !world.is_traversable(goal) {
        return None;
    }
    if start == goal {
        return Some(vec![start]);
    }
    const H: u64 = 9;
    let state = |cell: Cell, heading: usize| u64::from(cell) * H + heading as u64;
    let per_unit = params.v_lin * world.meta.resolution / f64::from(STRAIGHT);
    let heuristic = |cell: Cell| f64::from(octile(world, cell, goal)) * per_unit;
    // Eq. 2 time of a move, by previous heading (8: none) and heading.
    let step: [[f64; 8]; 9] = std::array::from_fn(|prev| {
        std::array::from_fn(|dir| {
            crate::eta::step_time(world, params, (prev < 8).then_some(prev), dir)
        })
    });
    let mut labels = StateStore::new(world.cell_count() as u64 * H);
    let mut heap = BinaryHeap::new();
    let first = state(start, NO_HEADING);
    labels.set(first, 0.0, NO_HEADING as u8);
    heap.push(Reverse((Seconds(heuristic(start)), first)));
    let mut reached = None;
    while let Some(Reverse((Seconds(f), s))) = heap.pop() {
        let (cell, heading) = ((s / H) as Cell, (s % H) as usize);
        let t = labels.time(s);
        if f > t + heuristic(cell) {
            continue; // a stale entry
        }
        if cell == goal {
            reached = Some(s);
            break;
        }
        for (dir, &dt) in step[heading].iter().enumerate() {
            let Some(next) = world.step(cell, dir) else {
                continue;
            };
            let nt = t + dt;
            let ns = state(next, dir);
            if nt < labels.time(ns) {
                labels.set(ns, nt, heading as u8);
                heap.push(Reverse((Seconds(nt + heuristic(next)), ns)));
            }
        }
    }
    // Walk back: the state's heading is the move that entered its cell.
    let mut s = reached?;
    let mut path = vec![(s / H) as Cell];
    while (s % H) as usize != NO_HEADING {
        let (cell, heading) = ((s / H) as Cell, (s % H) as usize);
        let (dx, dy) = MOVES[heading];
        let (x, y) = world.xy(cell);
        let prev = world.cell(
            (x as i64 - i64::from(dx)) as usize,
            (y as i64 - i64::from(dy)) as usize,
        );
        s = state(prev, usize::from(labels.from(s)));
        path.push(prev);
    }
    path.reverse();
    Some(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eta::path_eta;
    use crate::params::GaParams;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::Grid;

    fn world(w: u32, h: u32, blocked: &[(u32, u32)]) -> World {
        let meta = GridMeta {
            width: w,
            height: h,
            resolution: 0.2,
            origin: Origin::default(),
        };
        let mut occupancy = Grid::filled(meta, 0i8);
        for &(x, y) in blocked {
            occupancy.cells[(y * w + x) as usize] = 100;
        }
        World::new(&occupancy, &Grid::filled(meta, 0u8), 0.25).expect("world")
    }

    fn is_path(world: &World, path: &[Cell], start: Cell, goal: Cell) -> bool {
        path.first() == Some(&start)
            && path.last() == Some(&goal)
            && path.windows(2).all(|w| world.is_legal_move(w[0], w[1]))
    }

    /// Eq. 2 charges turns, so the path of least time is no slower than the shortest
    /// path by distance, and on an open floor it turns at most once. (Where the two
    /// differ in time, on the built-in world: `tests/plans.rs`.)
    #[test]
    fn the_fastest_path_is_never_slower_than_the_shortest_and_turns_less() {
        let params = GaParams::default();
        let world = world(40, 30, &[]);
        for (sx, sy, gx, gy) in [(1, 1, 30, 9), (2, 20, 35, 3), (5, 5, 6, 28), (0, 0, 39, 29)] {
            let (s, g) = (world.cell(sx, sy), world.cell(gx, gy));
            let shortest = shortest_path(&world, s, g).expect("shortest");
            let fastest = fastest_path(&world, &params, s, g).expect("fastest");
            assert!(is_path(&world, &fastest, s, g));
            let (ts, tf) = (
                path_eta(&world, &params, &shortest),
                path_eta(&world, &params, &fastest),
            );
            assert!(tf <= ts + 1e-12, "{tf} > {ts}");
            // At most one turn of 45° on an open floor.
            let straight = fastest.len() as f64 - 1.0;
            assert!(tf <= params.v_lin * 0.2 * straight * 2f64.sqrt() + params.v_ang * 0.8);
        }
    }

    /// Around obstacles too: A* over (cell, heading) against a brute force over every
    /// state (Dijkstra without a heuristic), on a world with a wall and a pillar.
    #[test]
    fn the_fastest_path_is_optimal_around_obstacles() {
        let mut blocked: Vec<(u32, u32)> = (0..14).map(|y| (10, y)).collect();
        blocked.extend([(20, 5), (21, 5), (20, 6), (21, 6)]);
        let world = world(30, 16, &blocked);
        let params = GaParams {
            v_ang: 3.0,
            ..GaParams::default()
        };
        let (s, g) = (world.cell(2, 2), world.cell(27, 3));
        let fastest = fastest_path(&world, &params, s, g).expect("path");
        assert!(is_path(&world, &fastest, s, g));
        // Brute force: relax every state until nothing changes.
        let n = world.cell_count() * 9;
        let mut best = vec![f64::INFINITY; n];
        best[s as usize * 9 + 8] = 0.0;
        loop {
            let mut changed = false;
            for st in 0..n {
                let t = best[st];
                if !t.is_finite() {
                    continue;
                }
                let (cell, h) = ((st / 9) as Cell, st % 9);
                for dir in 0..8 {
                    if let Some(next) = world.step(cell, dir) {
                        let nt =
                            t + crate::eta::step_time(&world, &params, (h < 8).then_some(h), dir);
                        let ns = next as usize * 9 + dir;
                        if nt < best[ns] - 1e-12 {
                            best[ns] = nt;
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                break;
            }
        }
        let optimum = (0..9)
            .map(|h| best[g as usize * 9 + h])
            .fold(f64::INFINITY, f64::min);
        assert!((path_eta(&world, &params, &fastest) - optimum).abs() < 1e-9);
        assert_eq!(fastest_path(&world, &params, s, s), Some(vec![s]));
        let walled = world.cell(10, 2);
        assert_eq!(fastest_path(&world, &params, s, walled), None);
    }
}
