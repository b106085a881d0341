//! A plain grid: where it sits in the world and its cells, row-major with row 0 at the
//! origin (the bottom of a map image).

use roam_proto::map::GridMeta;

/// Cells in one grid unless a service is configured otherwise: 16,777,216 = 4096², a
/// 1 km² site at 0.25 m (the map server's `max_layer_cells`). Every scenario or map a
/// service reads is bounded by it before its cells are allocated.
pub const DEFAULT_MAX_CELLS: u64 = 16_777_216;

/// A grid of `T` with its placement in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid<T> {
    pub meta: GridMeta,
    pub cells: Vec<T>,
}

impl<T: Copy> Grid<T> {
    /// A grid with every cell set to `value`.
    pub fn filled(meta: GridMeta, value: T) -> Self {
        let len = meta.width as usize * meta.height as usize;
        Grid {
            meta,
            cells: vec![value; len],
        }
    }

    pub fn width(&self) -> usize {
        self.meta.width as usize
    }

    pub fn height(&self) -> usize {
        self.meta.height as usize
    }

    /// The index of cell (x, y), or `None` outside the grid.
    pub fn index(&self, x: usize, y: usize) -> Option<usize> {
        (x < self.width() && y < self.height()).then(|| y * self.width() + x)
    }

    pub fn get(&self, x: usize, y: usize) -> Option<T> {
        self.index(x, y).map(|i| self.cells[i])
    }

    /// The cell containing world point (wx, wy), ignoring the origin's yaw (as Nav2's
    /// `worldToMap` does), or `None` outside the grid.
    pub fn cell_at(&self, wx: f64, wy: f64) -> Option<(usize, usize)> {
        world_to_cell(&self.meta, wx, wy)
    }
}

/// The cell containing world point (wx, wy), or `None` outside the grid.
pub fn world_to_cell(meta: &GridMeta, wx: f64, wy: f64) -> Option<(usize, usize)> {
    let fx = ((wx - meta.origin.x) / meta.resolution).floor();
    let fy = ((wy - meta.origin.y) / meta.resolution).floor();
    if fx < 0.0 || fy < 0.0 || fx >= f64::from(meta.width) || fy >= f64::from(meta.height) {
        return None;
    }
    Some((fx as usize, fy as usize))
}

/// The world point at the centre of cell (x, y).
pub fn cell_center(meta: &GridMeta, x: usize, y: usize) -> (f64, f64) {
    (
        meta.origin.x + (x as f64 + 0.5) * meta.resolution,
        meta.origin.y + (y as f64 + 0.5) * meta.resolution,
    )
}

/// ROS occupancy values.
pub mod occupancy {
    pub const UNKNOWN: i8 = -1;
    pub const FREE: i8 = 0;
    pub const OCCUPIED: i8 = 100;
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    #[test]
    fn world_points_map_to_cells_and_back() {
        let meta = GridMeta {
            width: 10,
            height: 5,
            resolution: 0.5,
            origin: Origin {
                x: -1.0,
                y: 2.0,
                yaw: 0.0,
            },
        };
        assert_eq!(world_to_cell(&meta, -1.0, 2.0), Some((0, 0)));
        assert_eq!(world_to_cell(&meta, 3.99, 4.49), Some((9, 4)));
        assert_eq!(world_to_cell(&meta, 4.0, 2.0), None);
        assert_eq!(world_to_cell(&meta, -1.01, 2.0), None);
        let (x, y) = cell_center(&meta, 3, 1);
        assert_eq!(world_to_cell(&meta, x, y), Some((3, 1)));
    }
}
