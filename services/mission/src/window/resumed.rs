//! The route a window was driving, as a successor executive finds it (`resume.rs` takes
//! it up; the handover carries it). A leaf: the window's other files import it.

use serde::{Deserialize, Serialize};

/// The route a window was driving, as its executive last sent it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Resumed {
    pub task: String,
    pub task_start_s: f64,
    /// A curious route (`false`: a fastest path).
    pub curious: bool,
    /// The route from where it was sent.
    pub points: Vec<[f64; 2]>,
}
