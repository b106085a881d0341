//! roam's map server.
//!
//! The algorithm side is plain Rust: [`ros_map`] reads and writes ROS `map_server`
//! maps as Nav2 does, [`scenario`] reads roam's scenario files, [`load_dirs`] confines loads from the wire
//! to the directories the operator named, [`layers`] computes the
//! inflated and heuristic layers, [`store`] holds versioned layers and the rules for
//! changing them, and [`persist`] keeps them on disk. [`service`] is the thin Zenoh
//! adapter around the store.

pub mod config;
pub mod distance;
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

pub use config::MapServerConfig;
pub use service::{run, MapServerError, SERVICE_NAME};
