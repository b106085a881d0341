//! roam's services as roles, and the ways to run them together.
//!
//! - [`roles`]: the role table. Every service roam runs (map server, planner, sim,
//!   localization, controller, mapper, mission) is one [`Role`]: its name, its config,
//!   the liveliness key it announces itself with, and how it runs. The `roam` binary's
//!   role commands, [`Stack`] and the integration tests' harness all start services
//!   through it, so a new role is added here and nowhere else.
//! - [`router`]: a Zenoh router inside roam (`roam router`, and the in-process router
//!   of the stack and the tests).
//! - [`stack`]: every service in one process around an in-process router on loopback
//!   (`roam stack`, `roam demo`, the benchmarks).

pub mod roles;
pub mod router;
pub mod stack;

pub use roles::{Role, RoleConfig};
pub use router::Router;
pub use stack::{Stack, StackError, StackOptions};
