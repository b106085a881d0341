//! The map a coarser planning grid was derived from ([`FineMap`]), and the limits of a
//! planning resolution ([`cell_factor`], [`ResolutionError`]).
//!
//! Apart from `resolution.rs`, which builds a coarse world and refines its paths, so
//! that a [`crate::world::World`] can hold its fine map without the world importing
//! the code that builds it: the planning grid sits below what derives it.

use roam_proto::map::GridMeta;
use roam_world::grid::{cell_center, world_to_cell};

use crate::cell::{Cell, MOVES};

/// Paper 000's grid (§II, §III: "a cell width of 20cm"): the default planning resolution.
pub const PAPER_RESOLUTION_M: f64 = 0.2;
/// The coarsest planning resolution: a planning cell of 2 m is ten of the paper's and
/// wider than any door; coarser would plan through walls' inflation and lose rooms.
pub const MAX_PLANNING_RESOLUTION_M: f64 = 2.0;
/// The most map cells along a planning cell's side (a block of 65,536 map cells).
pub const MAX_CELL_FACTOR: usize = 256;
/// The name of the setting, as in the config and the errors.
pub const LIMIT_NAME: &str = "planning_resolution_m";

/// A planning resolution that cannot be used with a map.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResolutionError {
    #[error("planning_resolution_m = {value} is not a positive number of metres; use ({map}, {MAX_PLANNING_RESOLUTION_M}] m, e.g. paper 000's 0.2")]
    Invalid { value: f64, map: f64 },
    #[error("planning_resolution_m = {value} m is finer than the map's resolution of {map} m: a planning cell cannot be smaller than a map cell; use at least {map} m (or leave it out: 0.2 m, paper 000's grid, or the map's resolution where that is coarser)")]
    FinerThanMap { value: f64, map: f64 },
    #[error("planning_resolution_m = {value} m is coarser than the limit of {max} m ({cells} map cells a side at the map's {map} m, at most {MAX_CELL_FACTOR}): planning cells that wide lose doors and rooms; use at most {max} m")]
    TooCoarse {
        value: f64,
        map: f64,
        max: f64,
        cells: f64,
    },
}

impl ResolutionError {
    /// The setting's name.
    pub fn name(&self) -> &'static str {
        LIMIT_NAME
    }
}

/// How many map cells of `map_resolution` a planning cell of `planning_resolution`
/// spans along each side: the ratio rounded to a whole number (a planning cell is a
/// block of map cells, so the effective planning resolution is `k · map_resolution`:
/// 0.21 m for 0.2 m on a 3 cm map). Refused when finer than the map (beyond rounding of
/// one part in a million), not a positive number, or coarser than
/// [`MAX_PLANNING_RESOLUTION_M`] or [`MAX_CELL_FACTOR`] map cells.
pub fn cell_factor(
    map_resolution: f64,
    planning_resolution: f64,
) -> Result<usize, ResolutionError> {
    let (value, map) = (planning_resolution, map_resolution);
    if !(value.is_finite() && value > 0.0) {
        return Err(ResolutionError::Invalid { value, map });
    }
    let ratio = value / map;
    let max = MAX_PLANNING_RESOLUTION_M.min(MAX_CELL_FACTOR as f64 * map);
    if value > MAX_PLANNING_RESOLUTION_M || ratio.round() > MAX_CELL_FACTOR as f64 {
        return Err(ResolutionError::TooCoarse {
            value,
            map,
            max,
            cells: ratio,
        });
    }
    if ratio < 1.0 - 1e-6 {
        return Err(ResolutionError::FinerThanMap { value, map });
    }
    Ok((ratio.round() as usize).max(1))
}

pub(crate) const FREE: u8 = 1;
pub(crate) const CORE: u8 = 2;

/// The map the planning grid was derived from: which map cells are free and which are
/// their block's core. One byte a map cell (1.7 MB for a 1.7-million-cell map); the
/// layers themselves are not kept.
#[derive(Debug, Clone)]
pub struct FineMap {
    pub meta: GridMeta,
    pub(crate) width: usize,
    pub(crate) height: usize,
    /// Map cells along a planning cell's side.
    pub factor: usize,
    /// Planning cells per row.
    pub(crate) coarse_width: usize,
    pub(crate) flags: Vec<u8>,
}

/// A map-cell index, `y · width + x` on the fine map.
pub type FineCell = u32;

impl FineMap {
    pub fn cell_count(&self) -> usize {
        self.flags.len()
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub(crate) fn xy(&self, c: FineCell) -> (usize, usize) {
        (c as usize % self.width, c as usize / self.width)
    }

    /// The map cell at a world point, if it is on the map.
    pub fn cell_at(&self, x: f64, y: f64) -> Option<FineCell> {
        world_to_cell(&self.meta, x, y).map(|(cx, cy)| (cy * self.width + cx) as FineCell)
    }

    /// Whether the robot may stand on a map cell (`inflated` is 0).
    pub fn is_free(&self, c: FineCell) -> bool {
        self.flags.get(c as usize).is_some_and(|f| f & FREE != 0)
    }

    /// Whether a map cell is in its block's core.
    pub fn in_core(&self, c: FineCell) -> bool {
        self.flags.get(c as usize).is_some_and(|f| f & CORE != 0)
    }

    /// The planning cell a map cell lies in.
    pub fn block_of(&self, c: FineCell) -> Cell {
        let (x, y) = self.xy(c);
        ((y / self.factor) * self.coarse_width + x / self.factor) as Cell
    }

    /// The map cell one step away in direction `dir`, if that step is legal: on the
    /// map, onto a free cell, a diagonal without cutting a corner.
    #[inline]
    pub fn step(&self, from: FineCell, dir: usize) -> Option<FineCell> {
        let (x, y) = self.xy(from);
        let (dx, dy) = MOVES[dir];
        let (nx, ny) = (x as i64 + i64::from(dx), y as i64 + i64::from(dy));
        let free = |x: i64, y: i64| {
            x >= 0
                && y >= 0
                && (x as usize) < self.width
                && (y as usize) < self.height
                && self.flags[y as usize * self.width + x as usize] & FREE != 0
        };
        if !free(nx, ny) || (dx != 0 && dy != 0 && !(free(nx, y as i64) && free(x as i64, ny))) {
            return None;
        }
        Some((ny as usize * self.width + nx as usize) as FineCell)
    }

    /// Whether `a → b` is one legal step on the map.
    pub fn is_legal_step(&self, a: FineCell, b: FineCell) -> bool {
        (0..MOVES.len()).any(|d| self.step(a, d) == Some(b))
    }

    /// A path as `[x, y]` map cells.
    pub fn grid_cells(&self, path: &[FineCell]) -> Vec<[u32; 2]> {
        path.iter()
            .map(|&c| {
                let (x, y) = self.xy(c);
                [x as u32, y as u32]
            })
            .collect()
    }

    /// The world points (map-cell centres) of a path.
    pub fn centers(&self, path: &[FineCell]) -> Vec<[f64; 2]> {
        path.iter()
            .map(|&c| {
                let (x, y) = self.xy(c);
                let (px, py) = cell_center(&self.meta, x, y);
                [px, py]
            })
            .collect()
    }

    /// The planning cells a path of map cells passes through, in order, each once per
    /// visit: what Eqs. 3 and 11 are summed over.
    pub fn planning_cells(&self, path: &[FineCell]) -> Vec<Cell> {
        let mut cells: Vec<Cell> = Vec::with_capacity(path.len() / self.factor + 2);
        for &c in path {
            let b = self.block_of(c);
            if cells.last() != Some(&b) {
                cells.push(b);
            }
        }
        cells
    }

    /// Per planning cell, the worst of `values` (one per map cell, passed through
    /// `capped`) over its core; `capped(NaN)` where a planning cell has no core.
    pub(crate) fn worst_per_cell(
        &self,
        values: &[f32],
        capped: impl Fn(f32) -> f32,
        planning_cells: usize,
    ) -> Vec<f32> {
        let mut worst = vec![f32::NEG_INFINITY; planning_cells];
        for (i, &v) in values.iter().enumerate() {
            if self.flags[i] & CORE != 0 {
                let b = self.block_of(i as FineCell) as usize;
                worst[b] = worst[b].max(capped(v));
            }
        }
        worst
            .into_iter()
            .map(|w| if w.is_finite() { w } else { capped(f32::NAN) })
            .collect()
    }
}
