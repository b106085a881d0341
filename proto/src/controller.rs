//! Messages of the APF controller (paper 002 §3): the mission a robot is given and the
//! controller's report on it.

use serde::{Deserialize, Serialize};

use crate::codec::Message;

/// The most waypoints one mission may hold.
pub const MAX_WAYPOINTS: usize = 10_000;

/// The longest mission id, bytes: it is echoed in every status, so it stays short.
pub const MAX_MISSION_ID_BYTES: usize = 128;

/// The longest JSON of one waypoint `[x,y],` as the codec writes it: two shortest
/// round-trip f64s (at most 24 characters each, e.g. `-2.2250738585072014e-308`) and
/// three separators.
const WAYPOINT_JSON_BYTES: usize = 2 * 24 + 4;

/// The largest mission payload a receiver decodes, bytes: [`MAX_WAYPOINTS`] waypoints at
/// their longest and 64 KiB for the envelope, the robot and the id (585,536 bytes).
/// Receivers (the controller, the view) check the size before they parse, so a 60 MB
/// mission costs nothing but its transfer.
pub const MAX_MISSION_BYTES: usize = MAX_WAYPOINTS * WAYPOINT_JSON_BYTES + 64 * 1024;

/// A mission for one robot, put on `<root>/robot/<id>/mission`: visit the waypoints in
/// order. A new mission replaces the current one at once; an empty one stops the robot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mission {
    /// The robot, as in the key.
    pub robot: String,
    /// The sender's name for the mission, echoed in every status; at most
    /// [`MAX_MISSION_ID_BYTES`].
    #[serde(deserialize_with = "crate::bounded::string::<MAX_MISSION_ID_BYTES, _>")]
    pub id: String,
    /// World metres; at most [`MAX_WAYPOINTS`] (the parse stops at one more).
    #[serde(deserialize_with = "crate::bounded::vec::<_, MAX_WAYPOINTS, _>")]
    pub waypoints: Vec<[f64; 2]>,
    /// A recovery: drive these waypoints even while the PEB is above the controller's
    /// guard (`max_peb_m`), to get a robot the guard holds back to where it had a fix.
    /// The executive sends one along the robot's own driven path, backwards; every
    /// other rule (stuck, step limit, stale estimates) still holds. Absent: `false`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub recovery: bool,
    /// The estimate step the sender decided the mission on (the executive sets it): the
    /// controller answers that estimate on the mission before and starts this one from
    /// the next. A mission that overtook the estimate it was decided on would otherwise
    /// answer it, and whether it did would depend on the machine's load. Absent: the
    /// mission starts at once.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after_step: Option<u64>,
}

impl Message for Mission {
    const KIND: &'static str = "mission";
}

/// Where a mission stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MissionState {
    /// No mission (or an empty one).
    Idle,
    /// Driving to the current waypoint.
    Active,
    /// Every waypoint was reached.
    Completed,
    /// No progress toward the waypoint over the controller's window: a local minimum of
    /// the potential field, or an oscillation. The robot is held until a new mission.
    Stuck,
    /// The PEB at the estimate is above the configured bound (or unbounded: the fix is
    /// lost). The robot is held while it lasts.
    HaltedPeb,
    /// No estimate arrived for the configured time. The robot is held until one does.
    HaltedStale,
    /// The mission used up the controller's step limit.
    StepLimit,
}

impl MissionState {
    /// Whether the mission is over for good (completed or given up): the controller
    /// drives it no more until a new mission.
    pub fn is_final(self) -> bool {
        matches!(
            self,
            MissionState::Completed | MissionState::Stuck | MissionState::StepLimit
        )
    }
}

/// The controller's report on a robot's mission, on `<root>/robot/<id>/controller`, after
/// every estimate and whenever the state changes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerStatus {
    pub robot: String,
    /// The mission's id; `None` before the first mission.
    pub mission: Option<String>,
    pub state: MissionState,
    /// Index of the current waypoint; `None` when there is none.
    pub waypoint: Option<usize>,
    pub waypoints: usize,
    /// Distance left along the remaining legs from the estimate, metres; `None` until
    /// the mission's first estimate.
    pub distance_left_m: Option<f64>,
    /// Commands sent for this mission.
    pub steps: u64,
    /// The step of the last estimate used.
    pub estimate_step: Option<u64>,
    /// The PEB of that estimate; `None` when unbounded or when there is none.
    pub peb_m: Option<f64>,
    /// The angle between the attractive and the information-seeking force, degrees
    /// (paper 002 Eq. 2's ω).
    pub omega_deg: f64,
    /// The information-seeking weight used, z_isa(ω) (paper 002 Eq. 2).
    pub z_isa: f64,
    /// The command sent, u of paper 002 Eq. 3.
    pub u: [f64; 2],
}

impl Message for ControllerStatus {
    const KIND: &'static str = "controller_status";
}
