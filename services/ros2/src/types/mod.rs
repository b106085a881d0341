//! The ROS 2 interface definitions roam speaks, as data: every field of every message
//! and service in order, with its type as REP-2011's type description numbers it.
//!
//! One table serves three readers: the RIHS01 type hashes ([`crate::hash`]), the
//! `ros2msg` schemas of a rosbag2 recording ([`message_definition`]), and the tests that
//! hold the serde structs of [`crate::msg`] to the same field order. The definitions are
//! those of ROS 2 Jazzy's `builtin_interfaces`, `std_msgs`, `geometry_msgs`, `nav_msgs`
//! and `service_msgs`, less their comments, constants and default values (none of which
//! are hashed), and roam's own `roam_interfaces/srv/PlanDowntime` (its `.srv` file ships
//! in `services/ros2/roam_interfaces/srv/`; a test checks the two agree).
mod actions;
mod def;
mod names;
mod table;
mod text;

pub use actions::*;
pub use def::{Base, Field, MsgDef, Shape};
pub use names::*;
pub use table::{all_messages, message, MESSAGES, SERVICES};
pub use text::{dependencies, message_definition, msg_text};
