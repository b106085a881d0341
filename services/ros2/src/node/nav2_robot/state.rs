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
pub(super) enum GoalEvent {
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
pub(super) struct Robot {
    pub(super) out: Arc<Output>,
    pub(super) follow_path: ActionClient,
    pub(super) config: Nav2Robot,
    pub(super) mission_clock: MissionClock,
    pub(super) estimate_key: String,
    pub(super) status_key: String,
    /// The mission being driven.
    pub(super) mission: Option<Mission>,
    /// Its FollowPath goal, once accepted.
    pub(super) goal: Option<Uuid>,
    pub(super) state: MissionState,
    pub(super) position: Option<[f64; 2]>,
    pub(super) last_pose: Option<Instant>,
    pub(super) step: u64,
    pub(super) steps: u64,
    pub(super) peb_m: Option<f64>,
    pub(super) distance_to_goal: Option<f64>,
}
