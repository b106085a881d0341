//! What a window leaves: its outcome, and what it hands the next window.

use roam_proto::mission::WindowReport;

use super::PlannedAhead;
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
}

impl Handover {
    /// What the first window begins with.
    pub fn first(margin: ArrivalMargin) -> Handover {
        Handover {
            margin,
            missions_sent: 0,
            asks_made: 0,
            planned_ahead: None,
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
