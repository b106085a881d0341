//! The library behind the `roam` binary: roam's main job (`roam demo`), the report
//! `roam stack --once` writes, and the PEB picture. `main.rs` only parses arguments and
//! calls in here, so the integration tests boot exactly what users run. The services
//! run as roles of `roam_stack`; experiments and benchmarks are `roam_experiments`.

pub mod demo;
pub mod peb_picture;
pub mod report;
