//! The library behind the `roam` binary: the in-process stack, the router role, the
//! report the stack writes, and the benchmark runners. `main.rs` only parses
//! arguments and calls in here, so the integration tests boot exactly what users run.

pub mod bench;
pub mod bench_fleet;
pub mod bench_load;
pub mod bench_localization;
pub mod bench_peer;
pub mod bench_planner;
pub mod bench_scaling;
pub mod bench_sim;
pub mod demo;
pub mod demo_today;
pub mod peb_picture;
pub mod report;
pub mod reproduce_apf;
pub mod reproduce_mapper;
pub mod reproduce_mission;
pub mod reproduce_planner;
pub mod router;
pub mod stack;
pub mod verdict;
