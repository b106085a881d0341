//! What every roam service and experiment shares about the world, built without Zenoh
//! or tokio, so that an estimator on a robot or an experiment in batch pulls in no
//! network stack:
//!
//! - [`grid`]: a grid with its placement in the world; [`distance`]: the exact
//!   Euclidean distance transform; [`layers`]: the inflated and heuristic layers made
//!   from an occupancy grid; [`render`]: grids and paths drawn to PNG; [`legend`]: a
//!   title, a legend and a scale bar around a picture, in the built-in [`font`].
//! - [`scenario`]: roam's scenario file (the map, zones of interest, places and the sim
//!   world's sections), its checks and loader, and the built-in world;
//!   [`ros_map`]: ROS `map_server` maps as Nav2 reads and writes them;
//!   [`load_dirs`]: which directories a load request from the wire may read.
//! - [`observation`]: what a robot sees of the grid (the sim's output, the mapper's input).
//! - [`world_id`]: which world a map is (one stack runs one world); [`epoch`]: message
//!   times checked against the sim clock, resets as new epochs.
//! - [`lock`]: a mutex's state even after a holder panicked.
//! - [`seed`]: the seeded random streams behind every random choice; [`noise`]: the
//!   Gaussian sampler and paper 002's TOA and transition noise drawn from them.

pub mod distance;
pub mod epoch;
pub mod font;
pub mod grid;
pub mod layers;
pub mod legend;
pub mod load_dirs;
pub mod lock;
pub mod noise;
pub mod observation;
pub mod param;
pub mod render;
pub mod ros_map;
pub mod scenario;
pub mod seed;
pub mod world_id;

pub use grid::{Grid, DEFAULT_MAX_CELLS};
pub use noise::ToaNoise;
pub use scenario::{Scenario, ScenarioError};
