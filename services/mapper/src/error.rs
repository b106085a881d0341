//! Why the mapper refused something. Every limit an error names is a constant of this
//! crate, so a caller can tell the user what to change.

use crate::limits::{MAX_MAP_CELLS, MAX_RESERVED_CELLS, MAX_RESERVING_ROBOTS};

/// Why the change map or the explorer refused an input. Nothing changes when a call is
/// refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapperError {
    #[error("the map has {cells} cells; the change map holds at most {max} (limit max_map_cells)")]
    MapTooLarge { cells: u64, max: u64 },
    #[error("the map has no cells: width and height must be at least 1")]
    EmptyMap,
    #[error("the map resolution {0} must be a positive number of metres per cell")]
    BadResolution(f64),
    #[error("parameter {field}: {reason}")]
    Param { field: &'static str, reason: String },
    #[error(
        "the observation window at ({x0}, {y0}) of {width} x {height} cells does not fit in \
         the {map_width} x {map_height} map; send windows inside the map"
    )]
    WindowOutside {
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
        map_width: u32,
        map_height: u32,
    },
    #[error("the observation window is {width} x {height} cells but carries {got} values")]
    WindowSize { width: u32, height: u32, got: usize },
    #[error(
        "observation value {value} at window cell {index}: use -1 (unseen) or 0..=100 \
         (0 free, 100 occupied)"
    )]
    BadValue { value: i8, index: usize },
    #[error("time {0} s is not a finite number")]
    BadTime(f64),
    #[error(
        "observation time {t} s is before the latest observation at {latest} s; send \
         observations in time order"
    )]
    TimeWentBack { t: f64, latest: f64 },
    #[error("cell ({x}, {y}) is outside the {width} x {height} map")]
    CellOffMap {
        x: i64,
        y: i64,
        width: u32,
        height: u32,
    },
    #[error(
        "robot {robot:?} cannot reserve: reservations are held for at most {max} robots \
         (limit max_reserving_robots); release another robot's first"
    )]
    TooManyRobots { robot: String, max: usize },
    #[error(
        "a reservation of more than {max} cells (limit max_reserved_cells); reserve the \
         plan's first {max} cells"
    )]
    ReservationTooLarge { max: usize },
    #[error(
        "a {got_width} x {got_height} grid was given where the {width} x {height} one of \
         the change map is expected; use grids of one size"
    )]
    GridMismatch {
        width: u32,
        height: u32,
        got_width: u32,
        got_height: u32,
    },
    #[error(
        "the belief has {belief} cells and the truth {truth}; give one value per cell to both"
    )]
    ScoreSizes { belief: usize, truth: usize },
    #[error("cell index {index} is outside the {cells} cells scored")]
    ScoreCellOff { index: usize, cells: usize },
    #[error("no cell to score: give at least one cell index")]
    ScoreEmpty,
    #[error("the belief at cell {index} is not a probability (NaN or -1 unknown); give 0..=1 or 0..=100")]
    NoBelief { index: usize },
}

impl MapperError {
    /// The size error for a map of `cells` cells.
    pub(crate) fn too_large(cells: u64) -> MapperError {
        MapperError::MapTooLarge {
            cells,
            max: MAX_MAP_CELLS,
        }
    }

    /// The robot-count error for `robot`.
    pub(crate) fn too_many_robots(robot: &str) -> MapperError {
        MapperError::TooManyRobots {
            robot: robot.chars().take(64).collect(),
            max: MAX_RESERVING_ROBOTS,
        }
    }

    /// The reservation-size error.
    pub(crate) fn reservation_too_large() -> MapperError {
        MapperError::ReservationTooLarge {
            max: MAX_RESERVED_CELLS,
        }
    }
}
