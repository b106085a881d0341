//! roam's curious planner (Spielbauer et al., "Roaming with Robots", paper 000).
//!
//! A robot with downtime asks for a path from where it stands to its next task that
//! gathers the most information and still arrives within the time it has. The
//! algorithm side is plain Rust over plain types:
//! - [`cell`]: a planning cell's index and the eight moves;
//! - [`world`]: the planning grid (traversable cells, information, heuristic blocks);
//! - [`params`]: the GA parameters, Table I's values as defaults;
//! - [`eta`]: the travel-time estimate t_ETA (Eq. 2);
//! - [`curiosity`]: the fitness (Eqs. 1, 3–7) with Models 0 / I / II (Eqs. 8–10);
//! - [`metrics`]: U_ges, D (Eqs. 11–12) and the information of distinct cells;
//! - [`ga`]: initialisation, layered selection, crossover, mutation (§II.A), with roam's
//!   round-trip rule for random walks;
//! - [`seeds`]: via-point seeds, paths through informative cells within the budget;
//! - [`greedy`]: a peer for the GA, via-points by information per second (model
//!   `greedy`);
//! - [`best`]: the plan is never below the shortest path or a seed;
//! - [`search`]: the fastest path (Eq. 2 over cell and heading: the baseline and the
//!   budget floor), the distance-shortest path and the distance field;
//! - [`resolution`]: the planning grid at a resolution apart from the map's, and the
//!   path the robot drives on the map's cells; [`fine`]: the map it is derived from,
//!   and the limits of a planning resolution;
//! - [`limits`]: what one plan may cost (path length from Eq. 2, memory, work);
//! - [`plan`]: one request end to end, with the checks that refuse bad requests;
//! - [`exact`]: the best possible plan of a small instance, by branch and bound, to
//!   measure the planners' gap to it.
//!
//! [`service`] is the thin Zenoh adapter, with what it needs against other clients:
//! [`queue`] (a bounded queue served in order, admission by expected wait),
//! [`budget`] (the CPU budget across clients), [`token`] and [`inflight`] (request
//! ids, cancel tokens, who may cancel), [`scope`] (a robot's plans on its own keys);
//! bounded logs and echoes of untrusted input come from `roam_runtime::warn_limit` and
//! `roam_proto::excerpt`, shared by every service.

pub mod answer;
pub mod best;
#[cfg(feature = "zenoh")]
pub mod budget;
pub mod cell;
#[cfg(feature = "zenoh")]
pub mod client;
#[cfg(feature = "zenoh")]
pub mod config;
pub mod coupling;
pub mod curiosity;
pub mod eta;
pub mod exact;
pub mod fine;
pub mod ga;
pub mod greedy;
#[cfg(feature = "zenoh")]
pub mod inflight;
pub mod limits;
pub mod maps;
pub mod metrics;
pub mod params;
pub mod plan;
#[cfg(feature = "zenoh")]
pub mod queue;
pub mod remainder;
pub mod resolution;
#[cfg(feature = "zenoh")]
pub mod scope;
pub mod search;
pub mod seeds;
pub mod seen;
#[cfg(feature = "zenoh")]
pub mod service;
pub mod token;
pub mod world;

#[cfg(feature = "zenoh")]
pub use config::PlannerConfig;
#[cfg(feature = "zenoh")]
pub use service::{run, SERVICE_NAME};
