//! The world the robots live in: the static grid, the anchors, the scripted blocks and
//! the random walkers, and the dynamic occupancy they make together at each step.

use rand_chacha::ChaCha8Rng;
use roam_proto::map::GridMeta;
use roam_world::grid::{cell_center, occupancy, world_to_cell, Grid};
use roam_world::scenario::{is_blocked, BlockSpec, Place, Scenario, WalkerSpec};
use serde::Serialize;

use crate::raster::CellXy;
use crate::semi_static::{ChangeZone, Objects, SemiStatic};
use roam_world::noise;

/// An anchor (paper 002 §2): a beacon at a known position, world metres.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Anchor {
    pub name: String,
    pub at: [f64; 2],
}

pub use crate::footprint::Footprint;

/// A scripted block: it holds each position of its path for `period_steps` steps and
/// cycles through the path (paper 004 §5, Fig. 3).
///
/// Paper 004 says only that "the top block changes position every 7 time steps and
/// moves over 6 positions, the bottom block changes position every 2 time steps and
/// moves on a cycle along the bottom wall". roam's reading: a block jumps from one listed
/// position to the next at steps that are multiples of the period, and returns to the
/// first after the last; a back-and-forth shuttle is written out as a path that goes
/// there and back. The block follows its script whatever is in the way (the script is
/// the ground truth the change-rate mapper estimates, so its period must never slip); a
/// robot it moves onto is put on the nearest free cell (see `Event::Displaced`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Block {
    pub name: String,
    pub footprint: Footprint,
    /// The cells the path's points fall in.
    pub path: Vec<CellXy>,
    pub period_steps: u32,
}

impl Block {
    /// The index in `path` of the position held at `step` (step 0 holds the first).
    pub fn index_at(&self, step: u64) -> usize {
        let len = self.path.len().max(1) as u64;
        ((step / u64::from(self.period_steps.max(1))) % len) as usize
    }

    /// The cell the block is centred on at `step`.
    pub fn centre_at(&self, step: u64) -> CellXy {
        self.path
            .get(self.index_at(step))
            .copied()
            .unwrap_or((0, 0))
    }
}

/// A random walker: every `every_steps` steps it draws one of the four axis directions
/// from the world's stream and moves `step_m` that way, or stays when its footprint
/// would leave the map or cover a wall, a block, another walker or a robot's cell. The
/// draw happens whether or not the move succeeds, so the world's stream does not depend
/// on where the robots are.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Walker {
    pub name: String,
    pub start: [f64; 2],
    /// Its position now, world metres.
    pub at: [f64; 2],
    pub footprint: Footprint,
    pub step_m: f64,
    pub every_steps: u32,
}

/// What is in a cell that a robot cannot enter.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Obstacle {
    /// An occupied (or unknown) cell of the static map.
    Wall,
    /// A scripted block, by name.
    Block(String),
    /// A random walker, by name.
    Walker(String),
    /// A semi-static object (a pallet), by its zone's name.
    Object(String),
    /// Outside the map.
    OffMap,
}

/// Why a world could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    #[error("the map has no cells")]
    Empty,
    #[error("{what} at ({x}, {y}) is outside the map")]
    OffMap { what: String, x: f64, y: f64 },
}

/// The static grid with everything that moves on it.
#[derive(Debug, Clone)]
pub struct World {
    meta: GridMeta,
    /// Whether each cell of the static map blocks (occupied or unknown).
    static_blocked: Vec<bool>,
    /// How many blocks and walkers cover each cell now.
    dynamic: Vec<u16>,
    anchors: Vec<Anchor>,
    blocks: Vec<Block>,
    walkers: Vec<Walker>,
    /// The step whose positions the blocks and walkers hold.
    step: u64,
    /// The world's own random stream (walkers).
    rng: ChaCha8Rng,
    /// The semi-static objects and their own stream.
    objects: Objects,
    /// Cells kept between a robot's cell and an object landing, each side.
    clearance_cells: i64,
}

impl World {
    /// The world of a scenario at step 0, its stream seeded by `seed`.
    pub fn new(scenario: &Scenario, seed: u64) -> Result<World, WorldError> {
        let grid = &scenario.occupancy;
        let meta = grid.meta;
        if grid.cells.is_empty() {
            return Err(WorldError::Empty);
        }
        let cell_of = |what: String, [x, y]: [f64; 2]| {
            world_to_cell(&meta, x, y)
                .map(|(cx, cy)| (cx as i64, cy as i64))
                .ok_or(WorldError::OffMap { what, x, y })
        };
        let file = &scenario.file;
        let anchors = file
            .anchors
            .iter()
            .map(|Place { name, at }| Anchor {
                name: name.clone(),
                at: *at,
            })
            .collect();
        let blocks = file
            .blocks
            .iter()
            .map(|b: &BlockSpec| {
                let footprint = match (b.size_cells, b.size_m) {
                    (Some([w, h]), _) => Footprint {
                        width_cells: w.max(1),
                        height_cells: h.max(1),
                    },
                    (None, Some(m)) => Footprint::from_metres(&meta, m),
                    (None, None) => Footprint {
                        width_cells: 1,
                        height_cells: 1,
                    },
                };
                let path = b
                    .path
                    .iter()
                    .enumerate()
                    .map(|(j, &p)| cell_of(format!("block '{}' position {j}", b.name), p))
                    .collect::<Result<Vec<_>, _>>()?;
                if path.is_empty() {
                    return Err(WorldError::OffMap {
                        what: format!("block '{}' (no positions)", b.name),
                        x: f64::NAN,
                        y: f64::NAN,
                    });
                }
                Ok(Block {
                    name: b.name.clone(),
                    footprint,
                    path,
                    period_steps: b.period_steps.max(1),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let walkers = file
            .walkers
            .iter()
            .map(|w: &WalkerSpec| {
                cell_of(format!("walker '{}'", w.name), w.at)?;
                Ok(Walker {
                    name: w.name.clone(),
                    start: w.at,
                    at: w.at,
                    footprint: Footprint::from_metres(&meta, [w.size_m, w.size_m]),
                    step_m: w.step_m,
                    every_steps: w.every_steps.max(1),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let zones = file
            .changes
            .iter()
            .map(|z| ChangeZone::new(z, &meta, file.time.step_s))
            .collect();
        // A robot's body, and a little room: an object never lands on a robot.
        let radius = file.robot_radius_m.unwrap_or(0.2) + 0.1;
        let mut world = World {
            meta,
            static_blocked: grid.cells.iter().map(|&v| is_blocked(v)).collect(),
            dynamic: vec![0; grid.cells.len()],
            anchors,
            blocks,
            walkers,
            step: 0,
            rng: noise::stream(seed, "world"),
            objects: Objects::new(zones, seed),
            clearance_cells: (radius / meta.resolution).ceil() as i64,
        };
        world.reset(seed);
        Ok(world)
    }

    /// Back to step 0: blocks at their first positions, walkers at their starts, the
    /// world's stream restarted from `seed`.
    pub fn reset(&mut self, seed: u64) {
        self.step = 0;
        self.rng = noise::stream(seed, "world");
        for w in &mut self.walkers {
            w.at = w.start;
        }
        self.objects.reset(seed);
        self.rebuild_dynamic();
    }

    /// Moves everything to the next step: blocks to their scripted positions, then each
    /// walker in turn (avoiding the cells in `robot_cells`).
    pub fn advance(&mut self, robot_cells: &[CellXy]) {
        self.step += 1;
        let step = self.step;
        for i in 0..self.blocks.len() {
            let (old, new) = (
                self.blocks[i].centre_at(step - 1),
                self.blocks[i].centre_at(step),
            );
            if old != new {
                let footprint = self.blocks[i].footprint;
                self.cover(footprint, old, false);
                self.cover(footprint, new, true);
            }
        }
        for i in 0..self.walkers.len() {
            if !step.is_multiple_of(u64::from(self.walkers[i].every_steps)) {
                continue;
            }
            // Always one draw per move tick; 2⁶⁴ is a multiple of 4, so no bias.
            let direction = rand::RngCore::next_u64(&mut self.rng) % 4;
            let w = &self.walkers[i];
            let [dx, dy] = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]][direction as usize];
            let target = [w.at[0] + dx * w.step_m, w.at[1] + dy * w.step_m];
            let (footprint, from) = (w.footprint, self.cell_of(w.at));
            let Some(to) = self.cell_of(target) else {
                continue;
            };
            if let Some(from) = from {
                self.cover(footprint, from, false);
            }
            let free = footprint.cells(to).all(|c| {
                self.index(c)
                    .is_some_and(|i| !self.static_blocked[i] && self.dynamic[i] == 0)
                    && !robot_cells.contains(&c)
            });
            if free {
                self.walkers[i].at = target;
            }
            if let Some(now) = self.cell_of(self.walkers[i].at) {
                self.cover(footprint, now, true);
            }
        }
        let statics = &self.static_blocked;
        let (w, h) = (i64::from(self.meta.width), i64::from(self.meta.height));
        let free =
            |(x, y): CellXy| x >= 0 && y >= 0 && x < w && y < h && !statics[(y * w + x) as usize];
        let reach = self.clearance_cells;
        let robot_on = |f: Footprint, centre: CellXy| {
            let (hw, hh) = (
                i64::from(f.width_cells) / 2 + reach + 1,
                i64::from(f.height_cells) / 2 + reach + 1,
            );
            robot_cells
                .iter()
                .any(|r| (r.0 - centre.0).abs() <= hw && (r.1 - centre.1).abs() <= hh)
        };
        let moves = self.objects.advance(step, free, robot_on);
        for (footprint, centre) in moves.left {
            self.cover(footprint, centre, false);
        }
        for (footprint, centre) in moves.landed {
            self.cover(footprint, centre, true);
        }
    }

    /// The semi-static objects now, landed or waiting for a robot to move off their
    /// place (the scenario's `changes`).
    pub fn objects(&self) -> &[SemiStatic] {
        self.objects.objects()
    }

    /// The zones the objects appear in.
    pub fn change_zones(&self) -> &[ChangeZone] {
        self.objects.zones()
    }

    /// Recounts the dynamic layer from the blocks' and walkers' positions now.
    fn rebuild_dynamic(&mut self) {
        self.dynamic.iter_mut().for_each(|c| *c = 0);
        for i in 0..self.blocks.len() {
            let (footprint, centre) = (
                self.blocks[i].footprint,
                self.blocks[i].centre_at(self.step),
            );
            self.cover(footprint, centre, true);
        }
        for i in 0..self.walkers.len() {
            let footprint = self.walkers[i].footprint;
            if let Some(centre) = self.cell_of(self.walkers[i].at) {
                self.cover(footprint, centre, true);
            }
        }
        let landed: Vec<_> = self
            .objects
            .objects()
            .iter()
            .filter(|o| o.landed_step.is_some())
            .map(|o| (o.footprint, o.centre))
            .collect();
        for (footprint, centre) in landed {
            self.cover(footprint, centre, true);
        }
    }

    /// Adds (or removes) one obstacle's footprint to the dynamic counts.
    fn cover(&mut self, footprint: Footprint, centre: CellXy, add: bool) {
        for c in footprint.cells(centre) {
            if let Some(i) = self.index(c) {
                let n = &mut self.dynamic[i];
                *n = if add {
                    n.saturating_add(1)
                } else {
                    n.saturating_sub(1)
                };
            }
        }
    }

    /// The index of a cell, or `None` off the map.
    pub fn index(&self, (x, y): CellXy) -> Option<usize> {
        let (w, h) = (i64::from(self.meta.width), i64::from(self.meta.height));
        (x >= 0 && y >= 0 && x < w && y < h).then(|| (y * w + x) as usize)
    }

    /// The cell a world point falls in, or `None` off the map.
    pub fn cell_of(&self, [x, y]: [f64; 2]) -> Option<CellXy> {
        world_to_cell(&self.meta, x, y).map(|(cx, cy)| (cx as i64, cy as i64))
    }

    /// The centre of a cell on the map, world metres.
    pub fn centre_of(&self, (x, y): CellXy) -> [f64; 2] {
        let (cx, cy) = cell_center(&self.meta, x.max(0) as usize, y.max(0) as usize);
        [cx, cy]
    }

    /// A world point in cell units (the grid's origin at 0, one cell per unit).
    pub fn to_cell_units(&self, [x, y]: [f64; 2]) -> [f64; 2] {
        [
            (x - self.meta.origin.x) / self.meta.resolution,
            (y - self.meta.origin.y) / self.meta.resolution,
        ]
    }

    /// Whether a robot may not be in this cell: off the map, a wall, a block or a walker.
    pub fn is_blocked(&self, cell: CellXy) -> bool {
        self.index(cell)
            .is_none_or(|i| self.static_blocked[i] || self.dynamic[i] > 0)
    }

    /// What blocks a cell, or `None` when it is free. A wall wins over a block, a block
    /// over a walker.
    pub fn obstacle_at(&self, cell: CellXy) -> Option<Obstacle> {
        let Some(i) = self.index(cell) else {
            return Some(Obstacle::OffMap);
        };
        if self.static_blocked[i] {
            return Some(Obstacle::Wall);
        }
        if self.dynamic[i] == 0 {
            return None;
        }
        if let Some(b) = self
            .blocks
            .iter()
            .find(|b| b.footprint.cells(b.centre_at(self.step)).any(|c| c == cell))
        {
            return Some(Obstacle::Block(b.name.clone()));
        }
        if let Some(w) = self.walkers.iter().find(|w| {
            self.cell_of(w.at)
                .is_some_and(|centre| w.footprint.cells(centre).any(|c| c == cell))
        }) {
            return Some(Obstacle::Walker(w.name.clone()));
        }
        self.objects
            .objects()
            .iter()
            .filter(|o| o.landed_step.is_some())
            .find(|o| o.footprint.cells(o.centre).any(|c| c == cell))
            .and_then(|o| self.objects.zones().get(o.zone))
            .map(|z| Obstacle::Object(z.name.clone()))
    }

    /// The occupancy now: the static map with every block and walker on it (ROS
    /// values: 100 occupied, 0 free, -1 unknown where the static map is unknown).
    pub fn occupancy(&self, static_map: &Grid<i8>) -> Grid<i8> {
        let mut grid = static_map.clone();
        for (cell, &n) in grid.cells.iter_mut().zip(&self.dynamic) {
            if n > 0 {
                *cell = occupancy::OCCUPIED;
            }
        }
        grid
    }

    /// The nearest cell a robot may be in, by 4-connected steps from `from` (ties: the
    /// first found in +x, +y, -x, -y order), or `None` when no cell is free.
    pub fn nearest_free(&self, from: CellXy) -> Option<CellXy> {
        let start = self.index(from)?;
        let mut seen = vec![false; self.static_blocked.len()];
        seen[start] = true;
        let mut queue = std::collections::VecDeque::from([from]);
        while let Some(c) = queue.pop_front() {
            if !self.is_blocked(c) {
                return Some(c);
            }
            for (dx, dy) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
                let n = (c.0 + dx, c.1 + dy);
                if let Some(i) = self.index(n) {
                    if !seen[i] {
                        seen[i] = true;
                        queue.push_back(n);
                    }
                }
            }
        }
        None
    }

    pub fn meta(&self) -> &GridMeta {
        &self.meta
    }

    /// The step whose positions the blocks and walkers hold.
    pub fn step(&self) -> u64 {
        self.step
    }

    pub fn anchors(&self) -> &[Anchor] {
        &self.anchors
    }

    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    pub fn walkers(&self) -> &[Walker] {
        &self.walkers
    }
}
