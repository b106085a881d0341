//! What can go wrong with a request to the localization algorithm. Each message says what
//! to change. Degenerate geometry is not an error: it gives a degraded result.

use roam_proto::number;

/// A request the localization algorithm refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LocalizationError {
    #[error("anchor {index} is at ({}, {}): anchor positions must be finite metres", number(at[0]), number(at[1]))]
    BadAnchor { index: usize, at: [f64; 2] },
    #[error("{count} anchors given, at most {max} are allowed: split the constellation")]
    TooManyAnchors { count: usize, max: usize },
    #[error("{name} is {}: it must be {expected}", number(*.value))]
    BadParameter {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error(
        "a range names anchor {index}, but the model has {count} anchors (indices 0..{count})"
    )]
    UnknownAnchor { index: usize, count: usize },
    #[error("{count} ranges given, at most {max} are allowed per estimate")]
    TooManyRanges { count: usize, max: usize },
    #[error("the range to anchor {index} is {}: a measured range must be a finite number of metres", number(*.value))]
    BadRange { index: usize, value: f64 },
    #[error("the point ({}, {}) is not finite: positions must be finite metres", number(at[0]), number(at[1]))]
    BadPoint { at: [f64; 2] },
    #[error("{count} points given, at most {max} are allowed: ask for fewer or use a grid")]
    TooManyPoints { count: usize, max: usize },
    #[error("the grid region is {width} x {height} cells: {reason}")]
    BadRegion {
        width: usize,
        height: usize,
        reason: String,
    },
}
