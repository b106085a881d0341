//! The planning grid: which cells the robot may occupy, which moves between them are
//! legal, their information scores, and the heuristic blocks of Model II.
//!
//! A world is at the map's resolution ([`World::new`]) or at a coarser planning
//! resolution derived from it ([`World::at_resolution`], `resolution`): then
//! it also holds the fine map it came from, on which the reply's path is driven.

use std::sync::Arc;

use roam_proto::map::GridMeta;
use roam_world::grid::{cell_center, world_to_cell, Grid};
use roam_world::layers::block_size;

use crate::fine::{FineMap, ResolutionError};

pub use crate::cell::{Cell, MOVES};

/// The grid the planner works on.
#[derive(Debug, Clone)]
pub struct World {
    pub meta: GridMeta,
    width: usize,
    height: usize,
    /// A cell is traversable when the inflated occupancy is free (0). Unknown cells
    /// are not: a plan never counts on space nobody has seen. (At a coarser planning
    /// resolution: when the robot can stand in it, `resolution`.)
    traversable: Vec<bool>,
    /// The legal moves out of each cell, bit `d` for [`MOVES`]`[d]`: onto a traversable
    /// cell on the map, and for a diagonal without cutting a corner (both orthogonal
    /// neighbours traversable). At a coarser planning resolution: where the fine map
    /// has a legal step from one cell's free space into the other's
    /// (`resolution`). Symmetric: a legal move a → b implies b → a.
    moves: Vec<u8>,
    /// Information scores I_xy, 0..=[`MAX_INFORMATION_SCORE`]: higher scores of the
    /// layer were clamped (see [`World::clamped`]).
    pub information: Vec<u8>,
    /// The scores above [`MAX_INFORMATION_SCORE`] the information layer had, if any.
    pub clamped: Option<Clamped>,
    /// Model II: the heuristic block of each cell and each block's cell count and
    /// initial sum of scores (paper 000 §II.B.3).
    pub block_of: Vec<u32>,
    pub block_cells: Vec<u32>,
    pub block_sums: Vec<f64>,
    /// The c_h the blocks were cut for.
    pub heuristic_compression: f64,
    /// The PEB at each cell, metres (localization's `peb` layer), for the
    /// localizability cost; empty when the planner has none. Unbounded cells are held
    /// at [`MAX_LOCALIZABILITY_COST_M`].
    pub localizability: Vec<f32>,
    /// Index difference of each move: `dx + dy · width`.
    move_offsets: [i64; 8],
    /// The map this grid was derived from, when it plans at a coarser resolution than
    /// the map's ([`World::at_resolution`]); `None` when it plans on the map's own cells.
    pub fine: Option<Arc<FineMap>>,
}

/// The highest information score I_xy (paper 000's scores, the map server's
/// `information` layer and the mapper's 100 · P(E > 0) are 0..=100).
///
/// The planner may be pointed at any u8 layer (`information_layer`), so a world clamps
/// higher scores to this one rather than refusing the map: a cell scored 255 is as
/// interesting as the most interesting cell, the planner keeps planning, and the map
/// cache logs the layer, how many cells were clamped and the first of them. (Model I
/// counts stimuli per score value, Eq. 9, in tables of 101 entries: a score above 100
/// used to panic the plan.)
pub const MAX_INFORMATION_SCORE: u8 = 100;

/// What clamping the information layer changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Clamped {
    /// Cells whose score was above [`MAX_INFORMATION_SCORE`].
    pub cells: usize,
    /// The first of them (row-major): column, row and the layer's score.
    pub first: (usize, usize, u8),
}

/// The legal moves of every cell of a `w × h` grid (see [`World`]'s `moves`): onto a
/// traversable cell on the map, diagonals without cutting a corner.
pub(crate) fn grid_moves(w: usize, h: usize, traversable: &[bool]) -> Vec<u8> {
    let mut moves = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            if !traversable[y * w + x] {
                // A cell the robot cannot stand on has no moves out: only a start there
                // could use them, and a start there is refused.
                continue;
            }
            let free = |x: i64, y: i64| {
                x >= 0
                    && y >= 0
                    && x < w as i64
                    && y < h as i64
                    && traversable[y as usize * w + x as usize]
            };
            let mut mask = 0u8;
            for (d, &(dx, dy)) in MOVES.iter().enumerate() {
                let (nx, ny) = (x as i64 + i64::from(dx), y as i64 + i64::from(dy));
                if free(nx, ny)
                    && (dx == 0 || dy == 0 || (free(nx, y as i64) && free(x as i64, ny)))
                {
                    mask |= 1 << d;
                }
            }
            moves[y * w + x] = mask;
        }
    }
    moves
}

/// The PEB a cell without a position fix counts as in the localizability cost, metres:
/// large against the decimetres of a covered area, finite so paths still compare.
pub const MAX_LOCALIZABILITY_COST_M: f32 = 10.0;

/// Why a world could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    #[error("the inflated map is {0}x{1} but the information map is {2}x{3}; both must cover the same cells")]
    SizeMismatch(u32, u32, u32, u32),
    #[error("the map has no cells")]
    Empty,
    #[error(transparent)]
    Resolution(#[from] ResolutionError),
}

impl World {
    /// Builds the planning grid from the inflated occupancy and the information map,
    /// with heuristic blocks at compression `c_h`.
    pub fn new(
        inflated: &Grid<i8>,
        information: &Grid<u8>,
        heuristic_compression: f64,
    ) -> Result<World, WorldError> {
        let (w, h) = (inflated.width(), inflated.height());
        if (information.width(), information.height()) != (w, h) {
            return Err(WorldError::SizeMismatch(
                inflated.meta.width,
                inflated.meta.height,
                information.meta.width,
                information.meta.height,
            ));
        }
        if w == 0 || h == 0 {
            return Err(WorldError::Empty);
        }
        let traversable: Vec<bool> = inflated.cells.iter().map(|&c| c == 0).collect();
        let moves = grid_moves(w, h, &traversable);
        World::from_parts(
            inflated.meta,
            traversable,
            moves,
            information,
            heuristic_compression,
            None,
        )
    }

    /// A world from its parts: what [`World::new`] and `resolution` build.
    /// Scores above [`MAX_INFORMATION_SCORE`] are clamped and reported in `clamped`.
    pub(crate) fn from_parts(
        meta: GridMeta,
        traversable: Vec<bool>,
        moves: Vec<u8>,
        information: &Grid<u8>,
        heuristic_compression: f64,
        fine: Option<Arc<FineMap>>,
    ) -> Result<World, WorldError> {
        let (w, h) = (meta.width as usize, meta.height as usize);
        if w == 0 || h == 0 {
            return Err(WorldError::Empty);
        }
        let over = information
            .cells
            .iter()
            .filter(|&&s| s > MAX_INFORMATION_SCORE)
            .count();
        let clamped = information
            .cells
            .iter()
            .position(|&s| s > MAX_INFORMATION_SCORE)
            .map(|i| Clamped {
                cells: over,
                first: (i % w, i / w, information.cells[i]),
            });
        let mut world = World {
            meta,
            width: w,
            height: h,
            traversable,
            moves,
            information: information
                .cells
                .iter()
                .map(|&s| s.min(MAX_INFORMATION_SCORE))
                .collect(),
            clamped,
            block_of: Vec::new(),
            block_cells: Vec::new(),
            block_sums: Vec::new(),
            heuristic_compression,
            localizability: Vec::new(),
            move_offsets: std::array::from_fn(|d| {
                i64::from(MOVES[d].0) + i64::from(MOVES[d].1) * w as i64
            }),
            fine,
        };
        world.set_heuristic_compression(heuristic_compression);
        Ok(world)
    }

    /// Sets the PEB per cell for the localizability cost (row-major, the world's size,
    /// or the fine map's on a world at a coarser planning resolution, where a planning
    /// cell takes the worst PEB of the free space it stands for; anything else clears
    /// it). NaN and values above [`MAX_LOCALIZABILITY_COST_M`] (an unbounded PEB: no fix
    /// there) count as that cap.
    pub fn set_localizability(&mut self, peb: &[f32]) {
        let capped = |v: f32| {
            if v.is_nan() {
                MAX_LOCALIZABILITY_COST_M
            } else {
                v.clamp(0.0, MAX_LOCALIZABILITY_COST_M)
            }
        };
        if peb.len() == self.cell_count() {
            self.localizability = peb.iter().map(|&v| capped(v)).collect();
        } else if let Some(fine) = self.fine.as_ref().filter(|f| f.cell_count() == peb.len()) {
            self.localizability = fine.worst_per_cell(peb, capped, self.cell_count());
        } else {
            self.localizability.clear();
        }
    }

    /// Recomputes the heuristic blocks for compression `c_h` (see
    /// [`roam_world::layers::heuristic`] for how blocks are cut).
    pub fn set_heuristic_compression(&mut self, compression: f64) {
        let (w, h) = (self.width, self.height);
        self.heuristic_compression = compression;
        let block = block_size(w, h, compression);
        let bw = w.div_ceil(block);
        let blocks = bw * h.div_ceil(block);
        self.block_of = vec![0; w * h];
        self.block_cells = vec![0; blocks];
        self.block_sums = vec![0.0; blocks];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let b = (y / block) * bw + x / block;
                self.block_of[i] = b as u32;
                self.block_cells[b] += 1;
                self.block_sums[b] += f64::from(self.information[i]);
            }
        }
    }

    /// This world with `cells` made untraversable: no moves into or out of them. For a
    /// client that plans its own fastest path round what the fleet has seen (the
    /// mission executive's straight routes, `roam_mission::window`), as the planner
    /// does with `obstacles_layer` (`crate::seen`); cells off the map are ignored.
    pub fn with_blocked(&self, cells: &[Cell]) -> World {
        let mut world = self.clone();
        for &cell in cells {
            let c = cell as usize;
            if c >= world.traversable.len() || !world.traversable[c] {
                continue;
            }
            world.traversable[c] = false;
            for d in 0..MOVES.len() {
                if let Some(n) = self.step(cell, d) {
                    if let Some(back) = self.direction(n, cell) {
                        world.moves[n as usize] &= !(1u8 << back);
                    }
                }
            }
            world.moves[c] = 0;
        }
        world
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub fn cell_count(&self) -> usize {
        self.width * self.height
    }

    pub fn cell(&self, x: usize, y: usize) -> Cell {
        (y * self.width + x) as Cell
    }

    pub fn xy(&self, cell: Cell) -> (usize, usize) {
        let c = cell as usize;
        (c % self.width, c / self.width)
    }

    pub fn is_traversable(&self, cell: Cell) -> bool {
        self.traversable
            .get(cell as usize)
            .copied()
            .unwrap_or(false)
    }

    pub fn traversable_count(&self) -> usize {
        self.traversable.iter().filter(|&&t| t).count()
    }

    /// The cell at a world point, if it is on the map.
    pub fn cell_at(&self, x: f64, y: f64) -> Option<Cell> {
        world_to_cell(&self.meta, x, y).map(|(cx, cy)| self.cell(cx, cy))
    }

    /// A path as `[x, y]` grid cells, as plans carry them on the wire.
    pub fn grid_cells(&self, path: &[Cell]) -> Vec<[u32; 2]> {
        path.iter()
            .map(|&c| {
                let (x, y) = self.xy(c);
                [x as u32, y as u32]
            })
            .collect()
    }

    /// The world points (cell centres) of a path.
    pub fn centers(&self, path: &[Cell]) -> Vec<[f64; 2]> {
        path.iter()
            .map(|&c| {
                let (x, y) = self.center(c);
                [x, y]
            })
            .collect()
    }

    /// The world point at the centre of a cell.
    pub fn center(&self, cell: Cell) -> (f64, f64) {
        let (x, y) = self.xy(cell);
        cell_center(&self.meta, x, y)
    }

    /// The cell one move away in direction `dir` (an index into [`MOVES`]), if that
    /// move is legal: on the map, onto a traversable cell, and for a diagonal move,
    /// not cutting a corner (both orthogonal neighbours traversable).
    #[inline]
    pub fn step(&self, from: Cell, dir: usize) -> Option<Cell> {
        let mask = *self.moves.get(from as usize)?;
        (mask & (1 << dir) != 0).then(|| (i64::from(from) + self.move_offsets[dir]) as Cell)
    }

    /// The resolution the robot drives at: the fine map's when this world plans at a
    /// coarser one, else its own.
    pub fn map_resolution(&self) -> f64 {
        self.fine
            .as_ref()
            .map_or(self.meta.resolution, |f| f.meta.resolution)
    }

    /// The direction index of the move from `a` to `b` if they are 8-neighbours.
    #[inline]
    pub fn direction(&self, a: Cell, b: Cell) -> Option<usize> {
        let (ax, ay) = self.xy(a);
        let (bx, by) = self.xy(b);
        let (dx, dy) = (bx as i64 - ax as i64, by as i64 - ay as i64);
        MOVES
            .iter()
            .position(|&(mx, my)| i64::from(mx) == dx && i64::from(my) == dy)
    }

    /// The direction of the move from `a` to `b` when `a` is at column `ax`, row `ay`,
    /// without dividing: the hot path of evaluation, which tracks positions itself.
    /// `None` when `b` is not an 8-neighbour of `a`.
    #[inline]
    pub fn move_between(&self, a: Cell, b: Cell, ax: usize, ay: usize) -> Option<usize> {
        let diff = i64::from(b) - i64::from(a);
        let dir = self.move_offsets.iter().position(|&o| o == diff)?;
        let (dx, dy) = MOVES[dir];
        let (nx, ny) = (ax as i64 + i64::from(dx), ay as i64 + i64::from(dy));
        (nx >= 0 && ny >= 0 && nx < self.width as i64 && ny < self.height as i64).then_some(dir)
    }

    /// A cell one legal move from `a` and one from `b`, the first in [`MOVES`] order:
    /// what joins two cells of a path that one move does not (a gap of one cell, a
    /// corner that cannot be cut). `None` when there is none.
    pub fn via(&self, a: Cell, b: Cell) -> Option<Cell> {
        (0..MOVES.len())
            .filter_map(|d| self.step(a, d))
            .find(|&c| self.is_legal_move(c, b))
    }

    /// Whether moving from `a` to `b` is one legal step.
    pub fn is_legal_move(&self, a: Cell, b: Cell) -> bool {
        self.direction(a, b).and_then(|d| self.step(a, d)) == Some(b)
    }

    /// Chebyshev distance in cells.
    pub fn chebyshev(&self, a: Cell, b: Cell) -> usize {
        let (ax, ay) = self.xy(a);
        let (bx, by) = self.xy(b);
        ax.abs_diff(bx).max(ay.abs_diff(by))
    }

    /// Manhattan distance in cells.
    pub fn manhattan(&self, a: Cell, b: Cell) -> usize {
        let (ax, ay) = self.xy(a);
        let (bx, by) = self.xy(b);
        ax.abs_diff(bx) + ay.abs_diff(by)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    #[test]
    fn a_blocked_cell_has_no_moves_in_or_out_and_the_rest_are_kept() {
        let meta = GridMeta {
            width: 5,
            height: 5,
            resolution: 0.2,
            origin: Origin::default(),
        };
        let world =
            World::new(&Grid::filled(meta, 0i8), &Grid::filled(meta, 0u8), 0.25).expect("world");
        let centre = world.cell(2, 2);
        let blocked = world.with_blocked(&[centre, 999]);
        assert!(!blocked.is_traversable(centre));
        assert_eq!(blocked.traversable_count(), world.traversable_count() - 1);
        for d in 0..MOVES.len() {
            assert_eq!(blocked.step(centre, d), None);
            let n = world.step(centre, d).expect("a neighbour");
            assert!(!(0..MOVES.len()).any(|e| blocked.step(n, e) == Some(centre)));
        }
        // A move elsewhere is kept.
        assert_eq!(
            blocked.step(world.cell(0, 0), 0),
            world.step(world.cell(0, 0), 0)
        );
        assert!(
            crate::search::shortest_path(&blocked, world.cell(0, 2), world.cell(4, 2))
                .is_some_and(|p| !p.contains(&centre))
        );
    }
}
