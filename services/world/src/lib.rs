//! What every roam service and experiment shares about the world, and builds without
//! Zenoh or tokio (an estimator on a robot, an experiment in batch):
//!
//! - [`seed`]: the seeded random streams behind every random choice, so that the same
//!   seed gives the same answer bit for bit in the sim, the mapper's explorer and the
//!   experiments.

pub mod seed;
