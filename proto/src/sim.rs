//! Messages of the sim world (papers 002 and 004): control, clock, commands, sensors.

use serde::{Deserialize, Serialize};

use crate::cells::Cells;
use crate::codec::Message;
use crate::map::GridMeta;

/// A request to the sim's control queryable `<root>/sim/control`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum SimControl {
    /// Load a scenario file (on the sim's machine) and reset with `seed`; paused.
    Load { path: String, seed: u64 },
    /// Put every robot back at its start, the blocks and walkers at step 0, and reseed.
    Reset { seed: u64 },
    /// Run `n` steps now (lock-step) and reply when they are published.
    Step { n: u32 },
    /// Stop free-running.
    Pause,
    /// Free-run at `rate` × real time (steps of `time.step_s`); 0 runs as fast as possible.
    Resume { rate: f64 },
    /// Add a robot at a world point.
    AddRobot { name: String, at: [f64; 2] },
    /// Remove a robot.
    RemoveRobot { name: String },
    /// Only report the status.
    Status,
}

impl Message for SimControl {
    const KIND: &'static str = "sim_control";
}

/// A named point: a robot or an anchor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedPoint {
    pub name: String,
    pub at: [f64; 2],
}

/// The sim's state, the reply to every control request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimStatus {
    /// The scenario's file name (`es1.yaml`), never a path on the sim's machine, or the
    /// built-in world's name.
    pub scenario: String,
    pub seed: u64,
    pub step: u64,
    pub time_s: f64,
    /// Free-running (`true`) or waiting for `step` requests.
    pub running: bool,
    /// The real-time factor when running; 0 means as fast as possible.
    pub rate: f64,
    pub step_s: f64,
    /// Free-running steps that finished after the next one was due (since the last
    /// load, reset or resume).
    #[serde(default)]
    pub late_steps: u64,
    /// Free-running steps since the last load, reset or resume.
    #[serde(default)]
    pub free_steps: u64,
    /// Robots at their true positions.
    pub robots: Vec<NamedPoint>,
    pub anchors: Vec<NamedPoint>,
    /// The commands waiting for the next step, by robot: the estimate step each answers
    /// (`RobotCommand::step`). A lock-step driver steps only once the command it saw
    /// leave the controller is here: the command and the driver's step request reach
    /// the sim on different links, in no promised order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pending: Vec<PendingCommand>,
}

/// A command the sim holds for its next step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PendingCommand {
    pub robot: String,
    /// The estimate step the command answers, if it names one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<u64>,
}

impl SimStatus {
    /// The share of free-running steps that finished before the next was due; 0 when
    /// none ran.
    pub fn on_time_share(&self) -> f64 {
        if self.free_steps == 0 {
            return 0.0;
        }
        1.0 - self.late_steps as f64 / self.free_steps as f64
    }
}

impl Message for SimStatus {
    const KIND: &'static str = "sim_status";
}

/// The sim clock, published on `<root>/sim/clock` after every step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimClock {
    pub step: u64,
    pub time_s: f64,
}

impl Message for SimClock {
    const KIND: &'static str = "sim_clock";
}

/// A motion command for one robot, put on `<root>/robot/<id>/cmd`: `u` of paper 002
/// Eq. 1. It applies to the next step only; a robot with no new command stands still.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotCommand {
    pub u: [f64; 2],
    /// The estimate's step the command answers, when it answers one (the controller sets
    /// it): lets a lock-step driver know that the command for step k has been sent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<u64>,
}

impl Message for RobotCommand {
    const KIND: &'static str = "robot_command";
}

/// One TOA range: the anchor (by name and position) and the measured distance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnchorRange {
    pub anchor: String,
    pub at: [f64; 2],
    pub range_m: f64,
}

/// A robot's TOA ranges in one step, on `<root>/robot/<id>/ranges`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeScan {
    pub robot: String,
    pub step: u64,
    pub time_s: f64,
    pub ranges: Vec<AnchorRange>,
}

impl Message for RangeScan {
    const KIND: &'static str = "range_scan";
}

/// What a robot saw of the grid in one step, on `<root>/robot/<id>/observation`:
/// a window of the map (`meta` places it in the world), ROS values -1 not seen, 0 free,
/// 100 occupied.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LocalObservation {
    pub robot: String,
    pub step: u64,
    pub time_s: f64,
    /// Where the sensor was, world metres: the pose the window was seen from (paper 004
    /// maps with known poses; a real sensor message carries its frame's pose the same way).
    pub at: [f64; 2],
    /// The window's lower-left cell in map coordinates.
    pub x0: u32,
    pub y0: u32,
    pub meta: GridMeta,
    pub cells: Cells,
}

impl Message for LocalObservation {
    const KIND: &'static str = "observation";
}

/// A robot's true position, on `<root>/robot/<id>/truth`: for evaluation only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundTruth {
    pub robot: String,
    pub step: u64,
    pub time_s: f64,
    pub at: [f64; 2],
}

impl Message for GroundTruth {
    const KIND: &'static str = "ground_truth";
}

/// The most objects an [`ObjectsTruth`] lists (a scenario's zones hold far fewer).
pub const MAX_OBJECTS_TRUTH: usize = 65_536;

/// The semi-static objects (the scenario's `changes`: pallets, obstacles) landed now, on
/// `<root>/sim/objects` in every step where one lands or leaves: for evaluation only,
/// as a robot's [`GroundTruth`] (how soon a fleet sees a change, how well its map
/// predicts the world now). Objects waiting for a robot to move off their place are
/// not in it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectsTruth {
    pub step: u64,
    pub time_s: f64,
    #[serde(deserialize_with = "crate::bounded::vec::<_, MAX_OBJECTS_TRUTH, _>")]
    pub objects: Vec<ObjectTruth>,
}

/// One landed object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectTruth {
    /// Unique over the sim's run (since its last load or reset), in order of start.
    pub id: u64,
    /// Its zone's index in the scenario's `changes`.
    pub zone: u32,
    /// The map cells it covers, inclusive: `[x0, y0, x1, y1]`.
    pub cells: [i64; 4],
}

impl Message for ObjectsTruth {
    const KIND: &'static str = "objects_truth";
}

/// Something that happened to a robot in a step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum RobotEventKind {
    /// The command asked for more than the top speed and was shortened.
    SpeedClipped { requested_m: f64, allowed_m: f64 },
    /// The move would have entered an occupied cell; the robot stopped short.
    Collision {
        target: [f64; 2],
        stopped_at: [f64; 2],
        cell: [i64; 2],
        obstacle: String,
    },
    /// A moving obstacle came onto the robot, which was put on the nearest free cell.
    Displaced {
        from: [f64; 2],
        to: [f64; 2],
        by: String,
    },
    /// A moving obstacle covers the robot and no free cell is left.
    Trapped { by: String },
}

/// A robot's events in one step, on `<root>/robot/<id>/events` (only when there are).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotEvents {
    pub robot: String,
    pub step: u64,
    pub events: Vec<RobotEventKind>,
}

impl Message for RobotEvents {
    const KIND: &'static str = "robot_events";
}
