//! roam's map server.
//!
//! The algorithm side is plain Rust: [`map_file`] reads the map or scenario the server
//! is pointed at (through `roam_world`'s ROS map and scenario readers), [`derived`]
//! keeps the inflated and heuristic layers (`roam_world::layers`) in step with a few
//! cell edits, [`store`] holds versioned layers and the rules for changing them,
//! [`edits`] is the checked form of a `set_cells` change, and [`persist`] keeps the
//! layers on disk (snapshots and change logs, see the crate's README). [`service`] is
//! the thin Zenoh adapter around the store.

#[cfg(feature = "zenoh")]
pub mod config;
pub mod derived;
pub mod edits;
pub mod map_file;
pub mod persist;
#[cfg(feature = "zenoh")]
pub mod service;
pub mod store;

#[cfg(feature = "zenoh")]
pub use config::MapServerConfig;
#[cfg(feature = "zenoh")]
pub use service::{run, MapServerError, SERVICE_NAME};
