//! What a window leaves: its outcome, and what it hands the next window.

use roam_proto::mission::WindowReport;

use super::resumed::Resumed;
use super::routes::PlannedAhead;
use crate::margin::ArrivalMargin;

/// A window's outcome with the paths, for pictures.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowOutcome {
    pub report: WindowReport,
    /// Every plan the robot was given in the window, in order.
    pub plans: Vec<Vec<[f64; 2]>>,
    /// The shortest path of the window, for comparison.
    pub shortest: Vec<[f64; 2]>,
    /// The estimates the robot drove on.
    pub driven: Vec<[f64; 2]>,
}

/// What one window hands the next.
#[derive(Debug, Clone, PartialEq)]
pub struct Handover {
    /// The arrival margin, as the window's drive taught it.
    pub margin: ArrivalMargin,
    /// Missions sent so far: their ids go on counting, so none is sent twice.
    pub missions_sent: u64,
    /// Plan requests made so far: their ids go on counting too.
    pub asks_made: u64,
    /// The next window's plan, made during this window.
    pub planned_ahead: Option<PlannedAhead>,
    /// The end of the robot's driven track (at most [`CARRIED_TRACK_POINTS`]) and the
    /// index in it of its last estimate with a fix: a robot still held when its window
    /// ends is driven back along it by the next window, instead of staying held where
    /// its new window's track has no fix to go back to.
    pub track: Vec<[f64; 2]>,
    pub fix: usize,
    /// The last set of believed obstacles heard: the next window checks its first
    /// route against it (a route planned ahead may predate it).
    pub obstacles: Option<std::sync::Arc<crate::seen::SeenObstacles>>,
    /// The route a predecessor executive was driving in this window (its
    /// `resume_file`), for a restarted executive's first window (`resume.rs`).
    pub resume: Option<Resumed>,
}

/// How much of a window's track the next one keeps: 600 estimates, four minutes at the
/// sim's 0.4 s step.
pub const CARRIED_TRACK_POINTS: usize = 600;

/// The last [`CARRIED_TRACK_POINTS`] of `driven` and `fix` as an index into them (the
/// oldest kept point when the fix is older).
pub(super) fn carried(driven: &[[f64; 2]], fix: usize) -> (Vec<[f64; 2]>, usize) {
    let start = driven.len().saturating_sub(CARRIED_TRACK_POINTS);
    (driven[start..].to_vec(), fix.saturating_sub(start))
}

impl Handover {
    /// What the first window begins with.
    pub fn first(margin: ArrivalMargin) -> Handover {
        Handover {
            margin,
            missions_sent: 0,
            asks_made: 0,
            planned_ahead: None,
            track: Vec::new(),
            fix: 0,
            obstacles: None,
            resume: None,
        }
    }
}

/// How a window ended.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowEnd {
    /// `None` for a skipped window.
    pub outcome: Option<WindowOutcome>,
    pub handover: Handover,
    /// The robot's last good estimate in the window (where it began if none came).
    pub position: [f64; 2],
}
