//! roam's experiments and benchmarks, in one home: each paper's evaluation reproduced
//! next to its published figures, the papers joined, and the benchmarks `roam bench`
//! runs. The services' crates hold the algorithms; this crate holds what is run *with*
//! them, so no service depends on another only for an experiment.
//!
//! - [`reproduce`]: `roam reproduce planner | apf | mapper | mission`: paper 000 §III,
//!   paper 002 §4 (ES1–ES3), paper 004 §5, and the papers joined (the executive's day
//!   in batch), each with its claims judged by [`verdict`]'s one rule.
//! - [`closed_loop`]: the sim, localization and the APF controller in one loop without
//!   a network, one run at a time ([`closed_loop::episode`]) or a step at a time with
//!   missions changed between steps ([`closed_loop::stepper`]).
//! - [`bench`]: `roam bench …`, each printing JSON.
//! - [`parallel`]: runs spread over threads, put back in order before anything is summed.
//! - [`progress`]: how a long run reports how far it is (the binary draws it).
//! - [`error`]: [`ExperimentError`], what a run or a benchmark can fail with.

pub mod bench;
pub mod closed_loop;
pub mod error;
pub mod parallel;
pub mod progress;
pub mod reproduce;
pub mod verdict;

pub use error::ExperimentError;
