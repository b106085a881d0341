//! roam's map server.
//!
//! The algorithm side is plain Rust: [`ros_map`] reads and writes ROS `map_server`
//! maps as Nav2 does, [`scenario`] reads roam's scenario files, [`load_dirs`] confines
//! loads from the wire to the directories the operator named, [`layers`] computes the
//! inflated and heuristic layers and [`derived`] keeps them in step with a few cell
//! edits, [`store`] holds versioned layers and the rules for changing them, [`edits`]
//! is the checked form of a `set_cells` change, and [`persist`] keeps the layers on
//! disk (snapshots and change logs, see the crate's README). [`service`] is the thin
//! Zenoh adapter around the store.

pub mod config;
pub mod derived;
pub mod distance;
pub mod edits;
pub mod grid;
pub mod layers;
pub mod load_dirs;
pub mod map_file;
pub mod persist;
pub mod render;
pub mod ros_map;
pub mod scenario;
pub mod service;
pub mod store;
pub mod world;
pub mod world_check;

pub use config::MapServerConfig;
pub use service::{run, MapServerError, SERVICE_NAME};
