//! What the executive is doing, as the progress display is told.

use roam_proto::planner::PlannerModel;

/// What the executive is doing, for a progress display.
#[derive(Debug, Clone, PartialEq)]
pub enum Progress {
    Planned {
        window: usize,
        task: String,
        budget_s: f64,
        eta_s: f64,
        curious: bool,
        /// The plan's probability of arriving late ([`crate::margin`]).
        late_probability: f64,
    },
    Replanned {
        window: usize,
        reason: String,
    },
    /// The PEB guard held the robot this long: it is driven back to its last fix.
    Recovering {
        window: usize,
        held_s: f64,
    },
    Arrived {
        window: usize,
        task: String,
        at_s: f64,
        start_s: f64,
    },
    GaveUp {
        window: usize,
        task: String,
    },
    /// The task was over before its window began: the executive was down through it
    /// (restarted after a crash). Nothing is driven or reported for it.
    Skipped {
        window: usize,
        task: String,
    },
    /// A plan came back: the model that made it and the wall seconds from the request
    /// to the answer (what a fleet's plan latency is measured by); `replan` when it
    /// was a replan seeded with the route the robot drives (what `roam bench planner
    /// --replans` measures in batch).
    Answered {
        window: usize,
        model: PlannerModel,
        took_s: f64,
        replan: bool,
    },
}
