//! What a robot sees of the grid: a window of the map around it, in ROS values. The
//! sim makes it (line of sight) and the mapper learns from it; it lives here, below
//! both, so neither depends on the other for it.

use serde::Serialize;

/// What a robot sees of the grid: a window of the map around it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Observation {
    /// The map cell at the window's lower-left corner.
    pub x0: u32,
    pub y0: u32,
    pub width: u32,
    pub height: u32,
    /// Row-major from (x0, y0), ROS values: -1 not seen, 0 free, 100 occupied (a wall, an
    /// unknown cell of the static map, a block or a walker).
    pub cells: Vec<i8>,
}

/// Not seen.
pub const UNSEEN: i8 = -1;
/// Seen, free.
pub const FREE: i8 = 0;
/// Seen, blocking.
pub const OCCUPIED: i8 = 100;

impl Observation {
    /// The value at map cell (x, y): `None` outside the window.
    pub fn get(&self, x: i64, y: i64) -> Option<i8> {
        let (dx, dy) = (x - i64::from(self.x0), y - i64::from(self.y0));
        if dx < 0 || dy < 0 || dx >= i64::from(self.width) || dy >= i64::from(self.height) {
            return None;
        }
        self.cells
            .get((dy * i64::from(self.width) + dx) as usize)
            .copied()
    }

    /// Every seen cell: map (x, y) and its value.
    pub fn seen(&self) -> impl Iterator<Item = (i64, i64, i8)> + '_ {
        let w = self.width.max(1) as usize;
        self.cells
            .iter()
            .enumerate()
            .filter(|(_, &v)| v != UNSEEN)
            .map(move |(i, &v)| {
                (
                    i64::from(self.x0) + (i % w) as i64,
                    i64::from(self.y0) + (i / w) as i64,
                    v,
                )
            })
    }
}
