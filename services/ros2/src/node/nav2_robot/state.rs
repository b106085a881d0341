//! What the robot's loop keeps, and what its goal tasks tell it.

use std::sync::Arc;
use std::time::Instant;

use roam_proto::controller::{Mission, MissionState};

use crate::msg::Uuid;
use crate::node::action_client::ActionClient;
use crate::node::output::Output;
use crate::node::sim_time::MissionClock;

use super::config::Nav2Robot;

/// What the goal tasks tell the robot's loop.
#[derive(Debug)]
pub(crate) enum GoalEvent {
    Accepted {
        mission: String,
        goal: Uuid,
    },
    Ended {
        mission: String,
        state: MissionState,
        why: String,
    },
}

/// One Nav2 robot as its loop drives it.
pub(crate) struct Robot {
    pub(crate) out: Arc<Output>,
    pub(crate) follow_path: ActionClient,
    pub(crate) config: Nav2Robot,
    pub(crate) mission_clock: MissionClock,
    pub(crate) estimate_key: String,
    pub(crate) status_key: String,
    /// The mission being driven.
    pub(crate) mission: Option<Mission>,
    /// Its FollowPath goal, once accepted.
    pub(crate) goal: Option<Uuid>,
    pub(crate) state: MissionState,
    pub(crate) position: Option<[f64; 2]>,
    pub(crate) last_pose: Option<Instant>,
    pub(crate) step: u64,
    pub(crate) steps: u64,
    pub(crate) peb_m: Option<f64>,
    pub(crate) distance_to_goal: Option<f64>,
}
