//! The ROS 2 messages roam sends and takes, as plain structs in the field order of
//! [`crate::types`] (serde writes fields in declaration order, which is CDR's order).

use serde::de::{SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// builtin_interfaces/msg/Time.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

impl Time {
    /// A time from nanoseconds since the epoch (saturating at `i32::MAX` seconds, 2038).
    pub fn from_nanos(ns: i64) -> Time {
        let ns = ns.max(0);
        let sec = (ns / 1_000_000_000).min(i64::from(i32::MAX));
        Time {
            sec: sec as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    pub fn as_nanos(self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }
}

/// std_msgs/msg/Header.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    pub stamp: Time,
    pub frame_id: String,
}

/// geometry_msgs/msg/Point.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// geometry_msgs/msg/Quaternion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

impl Default for Quaternion {
    /// The identity, as the message's own default (`w = 1`).
    fn default() -> Self {
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

impl Quaternion {
    /// A rotation by `yaw` radians about z.
    pub fn from_yaw(yaw: f64) -> Quaternion {
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: (yaw / 2.0).sin(),
            w: (yaw / 2.0).cos(),
        }
    }

    /// The rotation about z, radians (roll and pitch ignored).
    pub fn yaw(&self) -> f64 {
        let siny = 2.0 * (self.w * self.z + self.x * self.y);
        let cosy = 1.0 - 2.0 * (self.y * self.y + self.z * self.z);
        siny.atan2(cosy)
    }
}

/// geometry_msgs/msg/Pose.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position: Point,
    pub orientation: Quaternion,
}

/// geometry_msgs/msg/PoseStamped.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose,
}

/// The 6 × 6 row-major covariance of x, y, z, roll, pitch, yaw: a fixed CDR array (no
/// length), which serde's arrays (up to 32) do not reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Covariance(pub [f64; 36]);

impl Default for Covariance {
    fn default() -> Self {
        Covariance([0.0; 36])
    }
}

impl Serialize for Covariance {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut tuple = serializer.serialize_tuple(36)?;
        for v in &self.0 {
            tuple.serialize_element(v)?;
        }
        tuple.end()
    }
}

impl<'de> Deserialize<'de> for Covariance {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Elements;
        impl<'de> Visitor<'de> for Elements {
            type Value = Covariance;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("36 float64")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Covariance, A::Error> {
                let mut out = [0.0; 36];
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
                }
                Ok(Covariance(out))
            }
        }
        deserializer.deserialize_tuple(36, Elements)
    }
}

/// geometry_msgs/msg/PoseWithCovariance.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    pub pose: Pose,
    pub covariance: Covariance,
}

/// geometry_msgs/msg/PoseWithCovarianceStamped.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovarianceStamped {
    pub header: Header,
    pub pose: PoseWithCovariance,
}

/// nav_msgs/msg/MapMetaData.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct MapMetaData {
    pub map_load_time: Time,
    pub resolution: f32,
    pub width: u32,
    pub height: u32,
    pub origin: Pose,
}

/// nav_msgs/msg/OccupancyGrid.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct OccupancyGrid {
    pub header: Header,
    pub info: MapMetaData,
    /// Row-major, row 0 at the origin; -1 unknown, 0 free … 100 occupied.
    pub data: Vec<i8>,
}

/// nav_msgs/msg/Path.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Path {
    pub header: Header,
    pub poses: Vec<PoseStamped>,
}

/// nav_msgs/srv/GetPlan's request.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GetPlanRequest {
    pub start: PoseStamped,
    pub goal: PoseStamped,
    pub tolerance: f32,
}

/// nav_msgs/srv/GetPlan's response.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GetPlanResponse {
    pub plan: Path,
}

/// roam_interfaces/srv/PlanDowntime's request.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PlanDowntimeRequest {
    pub start: PoseStamped,
    pub goal: PoseStamped,
    pub budget_s: f64,
    pub model: String,
    pub seed: u64,
    pub deadline_s: f64,
}

/// roam_interfaces/srv/PlanDowntime's response.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PlanDowntimeResponse {
    pub path: Path,
    pub eta_s: f64,
    pub information: f64,
    pub within_budget: bool,
    pub reaches_goal: bool,
    pub error_code: String,
    pub error_message: String,
}

/// builtin_interfaces/msg/Duration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Duration {
    pub sec: i32,
    pub nanosec: u32,
}

impl Duration {
    /// A duration from seconds (negative and NaN as 0; saturating at `i32::MAX` s).
    pub fn from_secs_f64(seconds: f64) -> Duration {
        let ns = (seconds.max(0.0) * 1e9).min(f64::from(i32::MAX) * 1e9);
        let ns = if ns.is_finite() { ns as i64 } else { 0 };
        Duration {
            sec: (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// unique_identifier_msgs/msg/UUID: an action goal's id.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Uuid {
    pub uuid: [u8; 16],
}

/// action_msgs/msg/GoalInfo.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct GoalInfo {
    pub goal_id: Uuid,
    pub stamp: Time,
}

/// action_msgs/msg/GoalStatus.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct GoalStatus {
    pub goal_info: GoalInfo,
    /// One of [`GoalState`]'s values.
    pub status: i8,
}

/// action_msgs/msg/GoalStatus's `status` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(i8)]
pub enum GoalState {
    Unknown = 0,
    Accepted = 1,
    Executing = 2,
    Canceling = 3,
    Succeeded = 4,
    Canceled = 5,
    Aborted = 6,
}

impl GoalState {
    /// Succeeded, canceled or aborted: the goal's result is final.
    pub fn is_terminal(self) -> bool {
        matches!(
            self,
            GoalState::Succeeded | GoalState::Canceled | GoalState::Aborted
        )
    }
}

/// action_msgs/msg/GoalStatusArray: an action server's `_action/status` topic.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct GoalStatusArray {
    pub status_list: Vec<GoalStatus>,
}

/// action_msgs/srv/CancelGoal's request: a goal id, a stamp, both or neither (all).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CancelGoalRequest {
    pub goal_info: GoalInfo,
}

/// action_msgs/srv/CancelGoal's response.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CancelGoalResponse {
    /// One of the `CANCEL_*` codes.
    pub return_code: i8,
    pub goals_canceling: Vec<GoalInfo>,
}

/// CancelGoal's return codes (action_msgs/srv/CancelGoal's constants).
pub const CANCEL_NONE: i8 = 0;
pub const CANCEL_REJECTED: i8 = 1;
pub const CANCEL_UNKNOWN_GOAL_ID: i8 = 2;
pub const CANCEL_GOAL_TERMINATED: i8 = 3;

/// nav2_msgs/action/ComputePathToPose's goal.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ComputePathGoal {
    pub goal: PoseStamped,
    pub start: PoseStamped,
    pub planner_id: String,
    /// False: plan from the robot's current pose.
    pub use_start: bool,
}

/// nav2_msgs/action/ComputePathToPose's result.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ComputePathResult {
    pub path: Path,
    pub planning_time: Duration,
    /// 0, or one of [`Nav2Error`]'s codes.
    pub error_code: u16,
    pub error_msg: String,
}

/// nav2_msgs/action/ComputePathToPose's error codes (Jazzy's Result constants).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u16)]
pub enum Nav2Error {
    Unknown = 200,
    InvalidPlanner = 201,
    TfError = 202,
    StartOutsideMap = 203,
    GoalOutsideMap = 204,
    StartOccupied = 205,
    GoalOccupied = 206,
    Timeout = 207,
    NoValidPath = 208,
}

/// An action's `_action/send_goal` request: the goal `G` and its id.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SendGoalRequest<G> {
    pub goal_id: Uuid,
    pub goal: G,
}

/// An action's `_action/get_result` response: the goal's status and its result `R`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GetResultResponse<R> {
    pub status: i8,
    pub result: R,
}

/// An action's `_action/feedback` message: the feedback `F` of goal `goal_id`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FeedbackMessage<F> {
    pub goal_id: Uuid,
    pub feedback: F,
}

/// An action's `_action/send_goal` response.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SendGoalResponse {
    pub accepted: bool,
    pub stamp: Time,
}

/// An action's `_action/get_result` request.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct GetResultRequest {
    pub goal_id: Uuid,
}

/// rosgraph_msgs/msg/Clock: `/clock`, a simulation's time (`use_sim_time`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Clock {
    pub clock: Time,
}

/// std_msgs/msg/Empty: its one generated member.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Empty {
    pub structure_needs_at_least_one_member: u8,
}

/// nav2_msgs/action/FollowPath's goal.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FollowPathGoal {
    pub path: Path,
    pub controller_id: String,
    pub goal_checker_id: String,
    pub progress_checker_id: String,
}

/// nav2_msgs/action/FollowPath's result: an error code (0: none) and why.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FollowPathResult {
    pub result: Empty,
    pub error_code: u16,
    pub error_msg: String,
}

/// nav2_msgs/action/FollowPath's feedback.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FollowPathFeedback {
    pub distance_to_goal: f32,
    pub speed: f32,
}

/// geometry_msgs/msg/Vector3.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// geometry_msgs/msg/Transform.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    pub translation: Vector3,
    pub rotation: Quaternion,
}

/// geometry_msgs/msg/TransformStamped: `child_frame_id` in `header.frame_id`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    pub header: Header,
    pub child_frame_id: String,
    pub transform: Transform,
}

/// tf2_msgs/msg/TFMessage: what `/tf` and `/tf_static` carry.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    pub transforms: Vec<TransformStamped>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_round_trips() {
        for yaw in [0.0, 0.5, -1.2, 3.0] {
            assert!((Quaternion::from_yaw(yaw).yaw() - yaw).abs() < 1e-12);
        }
    }

    #[test]
    fn durations_are_seconds_and_nanoseconds() {
        assert_eq!(
            Duration::from_secs_f64(1.25),
            Duration {
                sec: 1,
                nanosec: 250_000_000
            }
        );
        assert_eq!(Duration::from_secs_f64(f64::NAN), Duration::default());
        assert_eq!(Duration::from_secs_f64(-3.0), Duration::default());
    }

    #[test]
    fn time_splits_nanoseconds() {
        let t = Time::from_nanos(1_700_000_000_123_456_789);
        assert_eq!((t.sec, t.nanosec), (1_700_000_000, 123_456_789));
        assert_eq!(t.as_nanos(), 1_700_000_000_123_456_789);
        assert_eq!(Time::from_nanos(-5), Time::default());
    }
}
