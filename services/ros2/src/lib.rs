//! roam in a ROS 2 system, over ROS 2's own Zenoh middleware (rmw_zenoh): no bridge
//! process, the same router, the same wire. See `services/ros2/README.md`.
//!
//! The wire, without Zenoh or tokio (what an offline tool or a test needs):
//!
//! - [`types`]: the interface definitions (fields in order) of every message and service;
//! - [`hash`]: their RIHS01 type hashes, computed as REP-2011 defines;
//! - [`msg`] and [`cdr`]: the messages and their CDR payloads;
//! - [`names`], [`wire`] and [`attachment`]: keys, liveliness tokens, QoS, GIDs and the
//!   33-byte attachment;
//! - [`convert`]: roam's layers, plans and estimates as ROS messages, and a ROS map and
//!   plan request as roam's;
//! - [`bag`]: a rosbag2 recording (MCAP, profile `ros2`);
//! - [`action`]: an action server's goals, states and cancel rules.
//!
//! With the default feature `zenoh`, [`node`] is the thin adapter: the `roam ros2` role.

pub mod action;
pub mod attachment;
pub mod bag;
pub mod cdr;
pub mod convert;
pub mod hash;
pub mod msg;
pub mod names;
#[cfg(feature = "zenoh")]
pub mod node;
pub mod types;
pub mod wire;
