//! roam's mission executive: what ties the papers together for one robot.
//!
//! The robot has fixed tasks (places and start times). Between two of them it has
//! downtime. For each window the executive asks the planner (paper 000) for a curious
//! path to the next task with t_exec = the time to the task's start minus what planning
//! costs, hands the path to the controller (paper 002) as waypoints, watches the robot's
//! estimates and the controller's status, replans when the robot is stuck (the path is
//! blocked), pushed off the path, or when its ETA slips past the task's start, and
//! reports each window: the information gathered, the arrival against the task's start,
//! the PEB along the way.
//!
//! - [`config`]: [`config::ExecutiveConfig`], the one configuration of the live
//!   executive and the batch; [`request`]: the planner request of a window's ask.
//! - [`tasks`]: the task sequence and its checks; the built-in world's day.
//! - [`site`]: a world and one robot's day in it: the built-in day or a user's Nav2
//!   map and day file.
//! - [`shift`]: a fleet's shift (each robot's tasks), the built-in warehouse's.
//! - [`day_check`]: a day checked against a map: every place free, every task
//!   reachable in time from the previous one (paper 000's fastest path).
//! - [`calibration`]: paper 000's time model (Eq. 2's v_lin, v_ang) fitted to what the
//!   robot drove, with Table I as the prior, kept per robot in a small file;
//!   [`resume`]: the route the robot drives, kept likewise for a restarted executive;
//!   [`state_file`]: how both are written and read.
//! - [`path`]: a planned path's waypoints (every turn kept); off-path distance; ETA slip.
//! - [`watch`]: the replan policy of a window (arrived, given up, lost mission, blocked,
//!   late, pushed off the path, slack), a plain state machine.
//! - [`window`]: one downtime window as a plain state machine around the watch (its
//!   plans, one planner request each; its mission; the arrival; the next window planned
//!   during the task; the report): events in, actions out.
//! - [`information`]: the information a path gathers, on the planner's own scale.
//! - `roam_experiments::reproduce::mission`: `roam reproduce mission`, the couplings
//!   compared in batch, and with `--days N` the executive's whole day in batch: the
//!   same window machine driven in process, once per configuration compared.
//! - [`executive`] (its [`error`]): the executive on Zenoh (a client of the planner, the controller,
//!   localization and the sim clock), a thin loop that feeds the window's machine and
//!   performs its actions; `inputs`: what it hears (clock, estimates, controller
//!   status, the world).
//! - [`service`]: `roam mission`, the executive as a service that publishes its reports.
//! - [`baseline`]: the demo's baseline, one plan per window and no replans, replayed in
//!   process beside the shipped executive's windows.

pub mod baseline;
pub mod calibration;
pub mod config;
pub mod day_check;
#[cfg(feature = "zenoh")]
pub mod error;
#[cfg(feature = "zenoh")]
pub mod executive;
pub mod information;
#[cfg(feature = "zenoh")]
mod inputs;
pub mod margin;
#[cfg(feature = "zenoh")]
mod obstacles;
pub mod path;
pub mod request;
pub mod resume;
pub mod seen;
#[cfg(feature = "zenoh")]
pub mod service;
pub mod shift;
pub mod site;
pub mod state_file;
pub mod tasks;
pub mod watch;
pub mod window;
