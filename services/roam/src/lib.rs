//! The library behind the `roam` binary: roam's main job (`roam demo`, the fleet's with
//! `--fleet`) and its picture
//! (`demo_picture`), the report `roam stack --once` writes, the PEB picture and the
//! frames of the other pictures (`pictures`).
//! `main.rs` only parses arguments and calls in here, so the integration tests boot
//! exactly what users run. The services run as roles of `roam_stack`; experiments and
//! benchmarks are `roam_experiments`.

pub mod demo;
pub mod demo_fleet;
pub mod demo_picture;
pub mod peb_picture;
pub mod pictures;
pub mod report;
