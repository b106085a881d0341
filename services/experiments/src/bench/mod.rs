//! `roam bench …`: each benchmark measures one thing on this machine and prints JSON.
//!
//! - [`map`]: get and publish of a ~1.7-million-cell layer through Zenoh;
//! - [`localization`]: WLS estimates per second and a PEB field;
//! - [`planner`]: the GA per curiosity model, in process and through the service;
//! - [`load`]: a burst of concurrent plan requests against two planners;
//! - [`sim`]: many robots publishing their sensors at a fixed rate;
//! - [`mapper`]: change-map observation updates per second;
//! - [`scaling`]: the planner's cost as the map gets finer, and its memory (issue 16);
//! - [`peer`]: the greedy planner against Model I at equal wall time (issue 16);
//! - [`fleet`]: robots in closed loop through Zenoh (issue 16).

pub mod fleet;
pub mod load;
pub mod localization;
pub mod map;
pub mod mapper;
pub mod peer;
pub mod planner;
pub mod process;
pub mod scaling;
pub mod sim;

use std::time::Duration;

/// A duration in milliseconds, as the benchmarks print them.
pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1000.0
}
