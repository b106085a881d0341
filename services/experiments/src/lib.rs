//! roam's experiments, in one home: each paper's evaluation reproduced next to its
//! published figures, and the papers joined. The services' crates hold the algorithms;
//! this crate holds what is run *with* them, so no service depends on another only for
//! an experiment. It builds without the network stack (no Zenoh, no tokio: CI checks
//! with `cargo tree`): a batch is the algorithms in process. The benchmarks, most of
//! which measure the services through Zenoh, are `roam-bench`.
//!
//! - [`reproduce`]: `roam reproduce planner | apf | mapper | mission`: paper 000 §III,
//!   paper 002 §4 (ES1–ES3), paper 004 §5, and the papers joined (the executive's day
//!   in batch), each with its claims judged by [`verdict`]'s one rule.
//! - [`closed_loop`]: the sim, localization and the APF controller in one loop without
//!   a network, one run at a time ([`closed_loop::episode`]) or a step at a time with
//!   missions changed between steps ([`closed_loop::stepper`]).
//! - [`parallel`]: runs spread over threads, put back in order before anything is summed.
//! - [`progress`]: how a long run reports how far it is (the binary draws it).
//! - [`error`]: [`ExperimentError`], what a run can fail with.

pub mod closed_loop;
pub mod error;
pub mod parallel;
pub mod progress;
pub mod reproduce;
pub mod verdict;

pub use error::ExperimentError;
