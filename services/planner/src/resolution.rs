//! A planning resolution apart from the map's (issue 16).
//!
//! Paper 000 plans on 20 cm cells (§II, §III); real sites publish maps at 2–5 cm, and
//! the GA's cost grows with the cells a path has, not with the trip: the paper's
//! workload took 5.4× as long on a 3 cm warehouse map as on the built-in 0.2 m world.
//! So the planner plans on a grid of *planning cells*, each a block of `k × k` map
//! cells (`k = round(planning_resolution / map_resolution)`, [`cell_factor`]), derived
//! from the map server's `inflated` and information layers, and drives the result on
//! the map's own cells.
//!
//! **Where the robot can pass.** The robot stands on a map cell whose `inflated` value
//! is 0 (free) and moves between 8-neighbours without cutting corners, as at the map's
//! resolution. In each block the free map cells fall into *fragments*, connected by such
//! steps inside the block; the largest fragment (the first in row-major order on a tie)
//! is the block's *core*: the free space the planning cell stands for.
//!
//! - A planning cell is traversable when its block has a free map cell (so a core).
//! - A move between neighbouring planning cells is legal when some core cell of the one
//!   has a legal map-cell step onto a core cell of the other. Diagonal moves need the
//!   corner cells, as a diagonal map step needs both its orthogonal neighbours.
//!
//! This keeps narrow doors open: a door whose inflated gap is one map cell wide (a door
//! one robot-width wide: the robot's centre has exactly one cell to pass) makes the
//! blocks it runs through traversable (their core is the gap, or the room the gap opens
//! into) and joins them with legal moves, where a rule like "every map cell free" would
//! close it. What it does not see: free space in a block that is not the block's core,
//! i.e. a block split by an obstacle thinner than the block. The inflated band around a
//! wall is at least two robot radii wide, so with a robot radius of at least half a
//! planning cell (0.1 m at the default 0.2 m) no block is split by a wall; a start or
//! goal in such a pocket is joined to a neighbouring planning cell whose core it touches
//! ([`locate`]), and refused only when there is none.
//!
//! **Information.** A planning cell's score is the most common score of its map cells
//! (the higher on a tie): Model I (Eq. 9) tracks stimuli by score value, so a planning
//! cell must carry a score the map has, not a blend of two stimuli, and a homogeneous
//! zone keeps its score. Eqs. 3 and 11 then sum the scores of planning cells in the
//! perception window, d = 3 planning cells wide: the paper's 20 cm cells at the default,
//! so F_1, U_ges, D and the distinct information mean what they mean in the paper, and
//! at every map resolution the same thing. The PEB (the localizability cost) of a
//! planning cell is the worst over its core.
//!
//! **The path the robot drives.** The GA plans on planning cells; [`refine`] turns a
//! planning path into map cells: the path of least Eq. 2 time on the map's cells that
//! passes through the cores of the planning path's cells in order (a search over
//! (planning-path index, map cell, heading) restricted to those cores: at most
//! `L · k² · 9` states). The legal-move rule guarantees it exists. Every cell of it is
//! free and every step legal on the fine `inflated` layer, and t_ETA and the budget
//! check are computed on it ([`FineMap::eta`]).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use roam_proto::map::GridMeta;
use roam_world::grid::Grid;

use crate::eta::step_time_at;
pub use crate::fine::{
    cell_factor, FineCell, FineMap, ResolutionError, LIMIT_NAME, MAX_CELL_FACTOR,
    MAX_PLANNING_RESOLUTION_M, PAPER_RESOLUTION_M,
};
use crate::fine::{CORE, FREE};
use crate::params::GaParams;
use crate::search::{StateStore, NO_HEADING, UNREACHED};
use crate::world::{Cell, World, WorldError, MOVES};

impl FineMap {
    /// t_ETA (Eq. 2) of a path of map cells, summed in order as
    /// [`crate::eta::path_eta`] sums it on planning cells.
    pub fn eta(&self, params: &GaParams, path: &[FineCell]) -> f64 {
        let mut t = 0.0;
        let mut prev = None;
        for pair in path.windows(2) {
            let ((ax, ay), (bx, by)) = (self.xy(pair[0]), self.xy(pair[1]));
            let (dx, dy) = (bx as i64 - ax as i64, by as i64 - ay as i64);
            match MOVES
                .iter()
                .position(|&(mx, my)| i64::from(mx) == dx && i64::from(my) == dy)
            {
                Some(dir) => {
                    t += step_time_at(self.meta.resolution, params, prev, dir);
                    prev = Some(dir);
                }
                None => {
                    t += params.v_lin * ((dx * dx + dy * dy) as f64).sqrt() * self.meta.resolution;
                    prev = None;
                }
            }
        }
        t
    }
}

impl World {
    /// The planning grid of `inflated` and `information` at `planning_resolution_m`
    /// (this module): the map's own cells when that is the map's resolution
    /// (to rounding, [`cell_factor`]), else cells of a whole number
    /// of map cells, holding the fine map to drive on. A planning resolution finer than
    /// the map's or coarser than [`MAX_PLANNING_RESOLUTION_M`] is
    /// refused naming the limit.
    pub fn at_resolution(
        inflated: &Grid<i8>,
        information: &Grid<u8>,
        heuristic_compression: f64,
        planning_resolution_m: f64,
    ) -> Result<World, WorldError> {
        let factor = cell_factor(inflated.meta.resolution, planning_resolution_m)?;
        if factor == 1 {
            return World::new(inflated, information, heuristic_compression);
        }
        if (information.width(), information.height()) != (inflated.width(), inflated.height()) {
            return Err(WorldError::SizeMismatch(
                inflated.meta.width,
                inflated.meta.height,
                information.meta.width,
                information.meta.height,
            ));
        }
        if inflated.width() == 0 || inflated.height() == 0 {
            return Err(WorldError::Empty);
        }
        coarse_world(inflated, information, heuristic_compression, factor)
    }
}

/// The planning grid of a map at `factor` map cells per planning cell (see the module
/// doc): [`World::at_resolution`] checks the inputs and calls this.
pub(crate) fn coarse_world(
    inflated: &Grid<i8>,
    information: &Grid<u8>,
    heuristic_compression: f64,
    factor: usize,
) -> Result<World, WorldError> {
    let (w, h, k) = (inflated.width(), inflated.height(), factor);
    let (cw, ch) = (w.div_ceil(k), h.div_ceil(k));
    let mut fine = FineMap {
        meta: inflated.meta,
        width: w,
        height: h,
        factor: k,
        coarse_width: cw,
        flags: inflated
            .cells
            .iter()
            .map(|&c| if c == 0 { FREE } else { 0 })
            .collect(),
    };
    let mut traversable = vec![false; cw * ch];
    let mut scores = vec![0u8; cw * ch];
    // Per block: its fragments, by flood fill inside the block; the largest is the core.
    let mut seen = vec![0u32; k * k];
    let mut stamp = 0u32;
    let (mut fragment, mut core, mut queue) = (Vec::new(), Vec::new(), Vec::new());
    for by in 0..ch {
        for bx in 0..cw {
            stamp += 1;
            core.clear();
            let (x0, y0) = (bx * k, by * k);
            let (x1, y1) = ((x0 + k).min(w), (y0 + k).min(h));
            let local = |c: usize| (c / w - y0) * k + (c % w - x0);
            let mut histogram = [0u32; 101];
            for y in y0..y1 {
                for x in x0..x1 {
                    let c = y * w + x;
                    histogram[usize::from(information.cells[c].min(100))] += 1;
                    if fine.flags[c] & FREE == 0 || seen[local(c)] == stamp {
                        continue;
                    }
                    fragment.clear();
                    queue.clear();
                    seen[local(c)] = stamp;
                    queue.push(c as FineCell);
                    while let Some(cell) = queue.pop() {
                        fragment.push(cell);
                        for dir in 0..MOVES.len() {
                            let Some(next) = fine.step(cell, dir) else {
                                continue;
                            };
                            let (nx, ny) = (next as usize % w, next as usize / w);
                            if nx < x0 || nx >= x1 || ny < y0 || ny >= y1 {
                                continue;
                            }
                            let l = local(next as usize);
                            if seen[l] != stamp {
                                seen[l] = stamp;
                                queue.push(next);
                            }
                        }
                    }
                    if fragment.len() > core.len() {
                        std::mem::swap(&mut fragment, &mut core);
                    }
                }
            }
            let b = by * cw + bx;
            // The most common score; the higher on a tie (the scan goes up).
            let mut mode = 0usize;
            for (score, &n) in histogram.iter().enumerate() {
                if n >= histogram[mode] {
                    mode = score;
                }
            }
            scores[b] = mode as u8;
            traversable[b] = !core.is_empty();
            for &c in &core {
                fine.flags[c as usize] |= CORE;
            }
        }
    }
    // Legal moves: a step from a core cell onto a core cell of a neighbouring block.
    let mut moves = vec![0u8; cw * ch];
    for c in 0..fine.flags.len() {
        if fine.flags[c] & CORE == 0 {
            continue;
        }
        let b = fine.block_of(c as FineCell) as usize;
        let (bx, by) = (b % cw, b / cw);
        for dir in 0..MOVES.len() {
            let Some(next) = fine.step(c as FineCell, dir) else {
                continue;
            };
            if fine.flags[next as usize] & CORE == 0 {
                continue;
            }
            let n = fine.block_of(next) as usize;
            if n == b {
                continue;
            }
            let (dx, dy) = ((n % cw) as i64 - bx as i64, (n / cw) as i64 - by as i64);
            if let Some(d) = MOVES
                .iter()
                .position(|&(mx, my)| i64::from(mx) == dx && i64::from(my) == dy)
            {
                moves[b] |= 1 << d;
            }
        }
    }
    let meta = GridMeta {
        width: cw as u32,
        height: ch as u32,
        resolution: inflated.meta.resolution * k as f64,
        origin: inflated.meta.origin,
    };
    let information = Grid {
        meta,
        cells: scores,
    };
    World::from_parts(
        meta,
        traversable,
        moves,
        &information,
        heuristic_compression,
        Some(std::sync::Arc::new(fine)),
    )
}

/// Where a start or goal map cell joins the planning grid.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Anchor {
    /// The map cell.
    pub fine: FineCell,
    /// The planning cell the plan starts or ends at.
    pub cell: Cell,
    /// When the map cell is not in its block's core: its fragment (sorted), which the
    /// driven path crosses to or from `cell`, a neighbouring planning cell whose core
    /// it touches.
    pub pocket: Option<Vec<FineCell>>,
}

/// Joins a free map cell to the planning grid: its planning cell when it is in that
/// cell's core, else the first neighbouring planning cell (in [`MOVES`] order) whose
/// core its fragment touches with a legal step. `None` when there is none (the cell is
/// in a pocket the planning grid does not reach).
pub fn locate(fine: &FineMap, world: &World, c: FineCell) -> Option<Anchor> {
    if !fine.is_free(c) {
        return None;
    }
    let block = fine.block_of(c);
    if fine.in_core(c) {
        return Some(Anchor {
            fine: c,
            cell: block,
            pocket: None,
        });
    }
    // The fragment of `c` inside its block (no core cell is in it: c is not).
    let k = fine.factor;
    let local = |c: FineCell| {
        let (x, y) = fine.xy(c);
        (y % k) * k + x % k
    };
    let mut seen = vec![false; k * k];
    seen[local(c)] = true;
    let mut fragment = vec![c];
    let mut i = 0;
    while i < fragment.len() {
        let cell = fragment[i];
        i += 1;
        for dir in 0..MOVES.len() {
            if let Some(next) = fine.step(cell, dir) {
                if fine.block_of(next) == block && !seen[local(next)] {
                    seen[local(next)] = true;
                    fragment.push(next);
                }
            }
        }
    }
    fragment.sort_unstable();
    let (bx, by) = world.xy(block);
    for &(dx, dy) in MOVES.iter() {
        let (nx, ny) = (bx as i64 + i64::from(dx), by as i64 + i64::from(dy));
        if nx < 0 || ny < 0 || nx >= world.width() as i64 || ny >= world.height() as i64 {
            continue;
        }
        let neighbour = world.cell(nx as usize, ny as usize);
        let touches = fragment.iter().any(|&a| {
            (0..MOVES.len()).any(|d| {
                fine.step(a, d)
                    .is_some_and(|b| fine.in_core(b) && fine.block_of(b) == neighbour)
            })
        });
        if touches {
            return Some(Anchor {
                fine: c,
                cell: neighbour,
                pocket: Some(fragment),
            });
        }
    }
    None
}

/// One stretch of the driven path: the core of a planning cell, or a pocket.
struct Stretch<'a> {
    block: Cell,
    pocket: Option<&'a [FineCell]>,
}

/// The path of map cells the robot drives for the planning path `planned` from
/// `start` to `goal` (see the module doc): the fastest by Eq. 2 on the map's cells
/// through the cores of `planned`'s cells in order. `None` only if `planned` is not a
/// path of legal moves from `start.cell` to `goal.cell`.
pub fn refine(
    fine: &FineMap,
    params: &GaParams,
    planned: &[Cell],
    start: &Anchor,
    goal: &Anchor,
) -> Option<Vec<FineCell>> {
    if start.fine == goal.fine && planned.len() <= 1 {
        return Some(vec![start.fine]);
    }
    let mut stretches: Vec<Stretch<'_>> = Vec::with_capacity(planned.len() + 2);
    if let Some(p) = &start.pocket {
        stretches.push(Stretch {
            block: fine.block_of(start.fine),
            pocket: Some(p),
        });
    }
    for &c in planned {
        if stretches
            .last()
            .is_none_or(|s| s.block != c || s.pocket.is_some())
        {
            stretches.push(Stretch {
                block: c,
                pocket: None,
            });
        }
    }
    if let Some(p) = &goal.pocket {
        stretches.push(Stretch {
            block: fine.block_of(goal.fine),
            pocket: Some(p),
        });
    }
    let n = stretches.len();
    let k = fine.factor;
    let k2 = (k * k) as u64;
    const H: u64 = 9;
    let member = |i: usize, c: FineCell| {
        let s = &stretches[i];
        fine.block_of(c) == s.block
            && match s.pocket {
                Some(p) => p.binary_search(&c).is_ok(),
                None => fine.in_core(c),
            }
    };
    let local = |c: FineCell| {
        let (x, y) = fine.xy(c);
        ((y % k) * k + x % k) as u64
    };
    let state = |i: usize, c: FineCell, h: usize| ((i as u64 * k2 + local(c)) * H) + h as u64;
    if !member(0, start.fine) || !member(n - 1, goal.fine) {
        return None;
    }
    let res = fine.meta.resolution;
    let step: [[f64; 8]; 9] = std::array::from_fn(|prev| {
        std::array::from_fn(|dir| step_time_at(res, params, (prev < 8).then_some(prev), dir))
    });
    let (gx, gy) = fine.xy(goal.fine);
    let heuristic = |c: FineCell| {
        let (x, y) = fine.xy(c);
        let (dx, dy) = (x.abs_diff(gx) as f64, y.abs_diff(gy) as f64);
        let (lo, hi) = (dx.min(dy), dx.max(dy));
        // Octile distance at v_lin, shrunk a hair so rounding never overestimates.
        params.v_lin * res * (hi - lo + lo * std::f64::consts::SQRT_2) * (1.0 - 1e-12)
    };
    // A state's stretch and map cell, from its index.
    let decode = |s: u64| {
        let (i, l) = ((s / H / k2) as usize, ((s / H) % k2) as usize);
        let block = stretches[i].block as usize;
        let (bx, by) = (block % fine.coarse_width, block / fine.coarse_width);
        let (x, y) = (bx * k + l % k, by * k + l / k);
        (i, (y * fine.width + x) as FineCell)
    };
    let mut labels = StateStore::new(n as u64 * k2 * H);
    let first = state(0, start.fine, NO_HEADING);
    labels.set(first, 0.0, NO_HEADING as u8);
    let mut heap = BinaryHeap::new();
    heap.push(Reverse((
        crate::search::Seconds(heuristic(start.fine)),
        first,
    )));
    let mut reached = None;
    while let Some(Reverse((crate::search::Seconds(f), s))) = heap.pop() {
        let (i, c) = decode(s);
        let h = (s % H) as usize;
        let t = labels.time(s);
        if f > t + heuristic(c) {
            continue;
        }
        if i == n - 1 && c == goal.fine {
            reached = Some(s);
            break;
        }
        for (dir, &dt) in step[h].iter().enumerate() {
            let Some(next) = fine.step(c, dir) else {
                continue;
            };
            let layer = if member(i, next) {
                i
            } else if i + 1 < n && member(i + 1, next) {
                i + 1
            } else {
                continue;
            };
            let nt = t + dt;
            let ns = state(layer, next, dir);
            if nt < labels.time(ns) {
                labels.set(ns, nt, h as u8);
                heap.push(Reverse((crate::search::Seconds(nt + heuristic(next)), ns)));
            }
        }
    }
    let mut s = reached?;
    let mut path = Vec::new();
    loop {
        let (i, c) = decode(s);
        path.push(c);
        let h = (s % H) as usize;
        if h == NO_HEADING {
            break;
        }
        let from = labels.from(s);
        if from == UNREACHED {
            return None;
        }
        let (dx, dy) = MOVES[h];
        let (x, y) = fine.xy(c);
        let prev = ((y as i64 - i64::from(dy)) as usize * fine.width
            + (x as i64 - i64::from(dx)) as usize) as FineCell;
        let layer = if member(i, prev) { i } else { i - 1 };
        s = state(layer, prev, usize::from(from));
    }
    path.reverse();
    Some(path)
}
