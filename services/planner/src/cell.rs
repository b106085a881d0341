//! A planning cell's index and the eight moves between cells: the ground every part
//! of the planner stands on (the world, its fine map, the searches).

/// A cell index, `y * width + x`.
pub type Cell = u32;

/// The eight moves, counter-clockwise from east; the index is the heading in units of 45°.
pub const MOVES: [(i32, i32); 8] = [
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
];
