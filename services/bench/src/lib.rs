//! `roam bench …`: each benchmark measures one thing on this machine and prints JSON.
//!
//! Apart from `roam-experiments` because most benchmarks measure the services through
//! Zenoh: the reproductions and the closed loop build without the network stack, the
//! benchmarks do not.
//!
//! - [`map`]: get and publish of a ~1.7-million-cell layer through Zenoh;
//! - [`localization`]: WLS estimates per second and a PEB field;
//! - [`planner`]: the GA per curiosity model, in process and through the service;
//! - [`load`]: a burst of concurrent plan requests against two planners;
//! - [`sim`]: many robots publishing their sensors at a fixed rate;
//! - [`mapper`]: change-map observation updates per second;
//! - [`scaling`]: the planner's cost as the map gets finer, and its memory;
//! - [`peer`]: the greedy planner against Model I at equal wall time;
//! - [`anytime`]: the anytime planner's plan at each deadline against the best known;
//! - [`optimality`]: the planners' plans against the exact optimum on small instances;
//! - [`fleet`]: robots in closed loop through Zenoh;
//! - [`chaos`]: the built-in day with every role killed, links cut, a planner frozen;
//! - [`wire`]: the wire's own latency, a put and a get, peer to peer and through a
//!   router, over TCP and TLS.

pub mod anytime;
pub mod chaos;
pub mod fleet;
pub mod load;
pub mod localization;
pub mod map;
pub mod mapper;
pub mod optimality;
pub mod peer;
pub mod planner;
pub mod process;
pub mod replans;
pub mod scaling;
pub mod sim;
mod spread;
pub mod wire;

use std::time::Duration;

/// A benchmark that could not run to its end; each says what was being set up or asked.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// The world, a scenario, a service or an output directory could not be made ready.
    #[error("{0}")]
    Setup(String),
    /// A request to a running service failed.
    #[error("the benchmark's request failed: {0}")]
    Client(#[from] roam_runtime::ClientError),
    /// A publication the benchmark waited for never came.
    #[error("no publication arrived within {0:?}")]
    Lost(Duration),
    /// Setting up what a benchmark shares with the experiments (the built-in world).
    #[error(transparent)]
    Experiment(#[from] roam_experiments::ExperimentError),
}

/// Any failure while a benchmark sets up, as [`BenchError::Setup`].
pub(crate) fn setup<E: std::fmt::Display>(e: E) -> BenchError {
    BenchError::Setup(e.to_string())
}

/// Waits until `publisher` sees a matching subscriber, at most `within`: declarations
/// propagate asynchronously, and a put before the match is lost to the measurement.
/// `false` when none matched in time.
pub(crate) async fn matched(publisher: &zenoh::pubsub::Publisher<'_>, within: Duration) -> bool {
    tokio::time::timeout(within, async {
        while !publisher
            .matching_status()
            .await
            .map(|s| s.matching())
            .unwrap_or(false)
        {
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    })
    .await
    .is_ok()
}

/// A duration in milliseconds, as the benchmarks print them.
pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1000.0
}
