//! roam's sim world: the world every other service is tested and demonstrated against.
//!
//! Plain Rust, no network and no async: a [`Sim`] is built from a scenario
//! (`roam_world::scenario`) and a seed, and stepped explicitly with motion commands;
//! each [`Sim::step`] returns what every robot did and sensed. The Zenoh service, the
//! CLI, the benchmark and the render are thin layers over this API.
//!
//! - `roam_world::noise` (shared with localization and the experiments): the seeded
//!   streams, a Gaussian sampler, paper 002's TOA noise (σ² up to d0, σ²((d/d0)^K + 1)
//!   beyond) and transition noise.
//! - [`world`]: the static grid, anchors, scripted blocks (paper 004), random walkers,
//!   the dynamic occupancy; [`semi_static`]: objects that appear in zones and vanish
//!   (the scenario's `changes`, a warehouse's pallets).
//! - [`robot`]: a robot and paper 002's motion model (Eq. 1) with a top speed and
//!   collisions; [`unicycle`]: roam's robot with a heading, which turns (at most
//!   w_max·dt per step) before it drives, so turning costs time as paper 000's Eq. 2
//!   assumes (`motion.model: { unicycle: ... }`); [`translate`]: one move against the
//!   world, where both end.
//! - [`sensors`]: TOA ranges to the anchors in range; [`los`]: the local grid observation
//!   with line of sight; [`raster`]: the cells a segment crosses.
//! - [`sim`]: [`Sim`], its step, reset, robots, reports and errors; [`event`]: what
//!   happened to a robot in a step.
//! - [`snapshot`]: the sim's clock and robots on disk, so a restarted sim service goes
//!   on where it was.
//!
//! Where papers 002 and 004 are ambiguous, the choice is written next to the code that
//! makes it and is a parameter of the scenario file: the exponent K and the step at d0
//! (`roam_world::noise::ToaNoise`), the range gate ([`sensors::ranges`]), how blocks move
//! ([`world::Block`]), the observation radius (`sensing.observation_radius_m`), the
//! top speed and the sim time per step (`motion`, `time`).

pub mod event;
pub mod footprint;
pub mod los;
pub mod messages;
pub mod raster;
pub mod render;
pub mod robot;
pub mod semi_static;
pub mod sensors;
#[cfg(feature = "zenoh")]
pub mod service;
pub mod sim;
pub mod snapshot;
pub mod translate;
pub mod unicycle;
pub mod world;

pub use event::Event;
pub use los::Observation;
pub use sensors::{Range, Readings};
pub use sim::{Command, RobotReport, Sim, SimError, SimParams, StepReport};
pub use world::{Anchor, Obstacle, World};
