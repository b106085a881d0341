//! Sim → ranges → localization → the APF controller → sim, in one process without a
//! network: [`episode`] runs a whole mission, [`stepper`] one step at a time with
//! missions changed between steps (the executive's day in batch), both from a
//! [`setup`].

pub mod episode;
pub mod setup;
pub mod stepper;

pub use episode::{load_scenario, run_episode, Episode, RobotMission, RobotTrack};
pub use setup::{EpisodeError, PositionSource, Setup};
pub use stepper::{RobotStep, StepOutcome, Stepper};
