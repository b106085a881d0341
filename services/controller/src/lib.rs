//! roam's APF controller with adaptive information seeking (paper 002, Lite & Rinner,
//! §3). The reproduction of the paper's experiments (§4) is `roam_experiments`'s.
//!
//! Plain Rust over plain types: no Zenoh, no async. A [`Controller`] turns a robot's
//! position (its localization estimate) and PEB into a motion command, paper 002 Eq. 3:
//!
//! ```text
//! u = z_a · f_a + z_r · f_Tr + z_isa(ω) · f_is
//! ```
//!
//! with f_a the unit vector to the current waypoint (or, under `follow: path`, to the
//! carrot of pure pursuit on the mission's path: [`carrot`]), f_Tr Khatib's repulsion of the
//! nearest obstacle, f_is the unit vector down the PEB's slope, and z_isa(ω) the
//! information-seeking weight that adapts to the angle ω between f_a and f_is (Eq. 2).
//! The Zenoh service ([`service`], a thin adapter) and the batch closed loop
//! (`roam_experiments::closed_loop`) run the same controller, on estimates from the same
//! [`roam_localization::Tracker`].
//!
//! | module | what it holds |
//! |---|---|
//! | [`params`] | [`ApfParams`]: paper 002 §4's values as defaults, roam's safety and path-following parameters, checks |
//! | [`carrot`] | pure pursuit on the mission's path: the forward-only projection and the carrot f_a pulls toward under `follow: path` |
//! | [`weights`] | [`Scheme`] and z_isa(ω) (Eq. 2) |
//! | [`forces`] | f_a, f_Tr, f_is's combination, ω, the command u (Eq. 3) |
//! | [`obstacle_field`] | η and the direction away from the nearest obstacle, from the exact EDT, built once per map |
//! | [`information`] | the PEB field of the anchors and f_is = unit(−∇PEB) |
//! | [`controller`] | the per-robot state machine (Idle, Active, Completed, Stuck, HaltedPeb, StepLimit) |
//! | [`service`] | the Zenoh adapter: missions and estimates in, commands and status out |
//!
//! # Where paper 002 is ambiguous, and what roam chose
//!
//! - **ω_t** is not stated; ES1's cutoff robot "due to its setup (i.e. ω = 90°…)" implies
//!   90° ([`params::DEFAULT_OMEGA_T_DEG`]). The cutoff scheme keeps `cutoff_keep · z_is`
//!   above ω_t (§3.1: "a percentage of z_is or completely disabled"; default 0).
//! - **f_is's magnitude** is not given: roam uses the unit vector of −∇PEB, so z_is is
//!   the IS force's strength relative to the unit attractive force (a raw PEB slope of
//!   ~0.01 m/m would make z_is = 0.8–0.9 meaningless). f_is is evaluated at the position
//!   the controller is given (the estimate; DESIGN.md), with roam-localization's central
//!   differences and its default step, 0.05 m.
//! - **f_a** is the unit vector to the waypoint (constant speed), not a quadratic
//!   potential's gradient; paper 002's ES1 robot drove 59.56 m in 296 steps of μ = 0.2,
//!   i.e. full-length steps throughout. Eq. 1 has no top speed, so where f_a and f_is
//!   agree the step is longer than μ (up to μ·(z_a + z_is) = 0.38 m): the ES scenarios
//!   cap a step at 0.4 m, which keeps Eq. 1 except next to walls, and lets the cutoff
//!   scheme "accelerate" toward waypoints as the paper's ES3 describes.
//! - **f_Tr** ("cumulative") is Khatib's force of the nearest obstacle cell, from a
//!   distance field measured to obstacle faces; off the map counts as an obstacle.
//! - **The mission RMSE** with runs of different lengths: RMSE^k over the runs still
//!   going at step k, averaged over k, over the successful runs (`roam_experiments::reproduce::apf`).
//! - **Safety** (not in the paper): a PEB above `max_peb_m` or unbounded holds the robot
//!   (HaltedPeb); no progress over `stuck_window_steps` ends the mission (Stuck). The
//!   reproduction turns the stuck rule off (`roam_experiments::reproduce::apf::paper::paper_params`), as the
//!   paper runs every mission to completion or max_steps, and ES2 turns the PEB guard off
//!   (true positions).
//! - **Scenarios**: the paper gives no coordinates. roam's ES1–ES3 scenarios
//!   (`config/scenarios/es*.yaml`) are built to have the properties the text describes;
//!   their comments say which. ES3's random missions are sampled as
//!   `roam_experiments::reproduce::apf::es3` documents.

pub mod carrot;
pub mod controller;
pub mod forces;
pub mod information;
pub mod obstacle_field;
pub mod params;
#[cfg(feature = "zenoh")]
pub mod service;
pub mod status;
pub mod weights;

#[cfg(test)]
mod goal_tolerance_tests;

pub use controller::{Controller, Decision, MissionState};
pub use information::InformationField;
pub use obstacle_field::ObstacleField;
pub use params::{ApfParams, Follow, ParamError};
pub use weights::{is_weight, Scheme};
