//! The mapper's named limits, apart so that its errors can name them without the
//! error type importing the code it reports on.

/// The most cells a change map holds (limit `max_map_cells`): 2048 × 2048. Each cell
/// costs about 49 bytes (its processes and its obstacle value), so the largest map
/// takes about 205 MB; a full-size warehouse map (1.7 M cells) about 84 MB.
pub const MAX_MAP_CELLS: u64 = 1 << 22;

/// The most robots holding a reservation at once (limit `max_reserving_robots`).
pub const MAX_RESERVING_ROBOTS: usize = 32;

/// The most cells one reservation holds (limit `max_reserved_cells`): 16 bytes each, so
/// 8 MB a robot.
pub const MAX_RESERVED_CELLS: usize = 1 << 19;
