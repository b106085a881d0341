//! Each paper's evaluation, reproduced and judged next to the paper's figures.
//!
//! - [`planner`]: paper 000 §III, Models 0 / I / II on the built-in world.
//! - [`apf`]: paper 002 §4, ES1–ES3 for plain APF and the four weighting schemes.
//! - [`mapper`]: paper 004 §5, curious against recency- and Poisson-only mapping.
//! - [`mission`]: the papers joined: seeded downtime missions, and the executive's
//!   whole day in batch.
//! - [`fleet`]: a fleet's week in the warehouse, against the patrol an operator would
//!   run (`roam reproduce fleet`).
//! - [`executive`]: the mission executive in process (its own window machine), one per
//!   robot, for the days and the fleet.

pub mod apf;
pub mod executive;
pub mod fleet;
pub mod mapper;
pub mod mission;
pub mod planner;
