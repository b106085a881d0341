//! Messages of the change-rate mapper and the curious exploration learner (paper 004).
//!
//! The mapper's layers travel as ordinary map-server layers (f32 cells) under the names
//! below; what is here is the exploration goal it publishes and the status it answers.

use serde::{Deserialize, Serialize};

use crate::codec::Message;

/// Layer of estimated change rates 1/T^c, events per second (paper 004 Eq. 1); 0 where
/// no change was seen.
pub const CHANGE_RATE_LAYER: &str = "change_rate";
/// Layer of P_c(E > 0), the probability that a cell changed since it was last seen
/// (paper 004 Eq. 2).
pub const CHANGE_PROBABILITY_LAYER: &str = "change_probability";
/// Layer of round(100 · P_c(E > 0)) as u8 scores 0–100: the change probability in the
/// form of paper 000's information map, for a planner configured with
/// `information_layer: change_information`.
pub const CHANGE_INFORMATION_LAYER: &str = "change_information";
/// Layer of recency r^c = t_now − t_last, seconds (paper 004 §3).
pub const RECENCY_LAYER: &str = "recency";
/// Layer of news scores round(100 · P_news) as u8 0–100: the probability that a cell
/// changed since any robot last saw it, each robot's current mission counted as seen
/// at the times it should pass (`roam_mapper::news`), for no robot in particular.
pub const NEWS_LAYER: &str = "news";
/// Layer of the fleet's belief that each cell is occupied now, ROS occupancy i8 0..=100
/// (never -1: a cell never seen holds its prior; `roam_mapper::belief`).
pub const OCCUPIED_NOW_LAYER: &str = "occupied_now";

/// A goal the learner chose for a robot, on `<root>/robot/<id>/goal`, when it chooses one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplorationGoal {
    pub robot: String,
    pub step: u64,
    pub time_s: f64,
    /// The goal cell's centre, world metres.
    pub goal: [f64; 2],
    /// `recency` or `poisson` (paper 004 §4's two strategies).
    pub strategy: String,
    /// Episodes finished so far by this robot.
    pub episodes: u64,
}

impl Message for ExplorationGoal {
    const KIND: &'static str = "exploration_goal";
}

/// A `get` on `<root>/mapper/status` (no payload) answers with this.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapperStatus {
    /// Observations merged into the map.
    pub observations: u64,
    /// Cells whose mapped value changed, over all observations.
    pub map_changes: u64,
    /// The learner's features at the last observation: p = Σ P_c(E > 0), r = max r^c
    /// (paper 004 Eq. 4).
    pub p: f64,
    pub r: f64,
    /// Times the layers were sent to the map server.
    pub layers_sent: u64,
    /// The robots the learner drives.
    pub explorers: Vec<ExplorerStatus>,
    /// The robots whose current mission the news value counts, by name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reservations: Vec<ReservationStatus>,
}

/// One robot's reservation: the cells its current mission will show it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReservationStatus {
    pub robot: String,
    pub cells: u64,
}

/// One driven robot's exploration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplorerStatus {
    pub robot: String,
    pub strategy: Option<String>,
    pub goal: Option<[f64; 2]>,
    pub episodes: u64,
}

impl Message for MapperStatus {
    const KIND: &'static str = "mapper_status";
}
