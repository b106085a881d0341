//! The Zenoh side: follows roam's keys and logs what it sees on the Foxglove topics.
//!
//! Two loops share the outputs. The *world* loop follows the map server's layers (each
//! publication; each delta, applied to the layer shown when it is the delta's base
//! version, else the whole layer is fetched; plus a look at `<root>/map/layers` at start
//! and every [`REFRESH_PERIOD`], fetching every layer whose version it has not shown: a
//! view started after the map server, or a map server restarted, is caught up) and asks the sim
//! for its anchors and robots on the same period. The *robots* loop follows the true
//! positions, the estimates and the missions.
//!
//! Nothing from the wire is trusted (see `wire`): every payload is checked against its
//! kind's cap before it is decoded, robot and layer names must be key segments and match
//! the key they came on, missions are held to the controller's limits, and every queue
//! and table is bounded: the subscribers are ring buffers (the oldest sample goes when
//! one is full), at most [`MAX_LAYERS`] layers of [`MAX_LAYER_BYTES_SHOWN`] together are
//! shown, and per-robot state (missions, driven paths) is kept for at most [`MAX_ROBOTS`]
//! robots each (see `roster`: the sim's own robots are never evicted by strangers).

mod limits;
mod robots;
mod samples;
mod topics;
mod world;

use std::collections::BTreeMap;
use std::sync::Arc;

use foxglove::messages::SceneUpdate;
use roam_runtime::FleetStreams;
use tokio::sync::watch;
use tokio_util::sync::CancellationToken;
use zenoh::Session;

use crate::output::Outputs;
use crate::roster::Roster;

use robots::Robots;
use samples::SimRobots;
use topics::RobotTopics;
use world::World;

pub use crate::roster::MAX_ROBOTS;
pub use limits::{
    DRIVEN_POINTS, MAX_LAYERS, MAX_LAYER_BYTES_SHOWN, MAX_LAYER_CELLS, REFRESH_PERIOD,
};
pub use topics::{ANCHORS_TOPIC, DRIVEN_TOPIC, ESTIMATE_TOPIC, MISSION_TOPIC, TRUTH_TOPIC};

/// Runs both loops until `cancel`.
pub(crate) async fn follow(
    session: Session,
    root: String,
    subscriptions: FleetStreams,
    out: Arc<Outputs>,
    cancel: CancellationToken,
) {
    let FleetStreams {
        layers,
        deltas,
        truth,
        estimate,
        mission,
    } = subscriptions;
    let robots = RobotTopics::new(&out);
    let anchors = out.topic::<SceneUpdate>(ANCHORS_TOPIC, true);
    let (sim_tx, sim_rx) = watch::channel(SimRobots::default());
    let world = World {
        out: out.clone(),
        root: root.clone(),
        session,
        layers: BTreeMap::new(),
        layer_bytes: 0,
        anchors_topic: anchors,
        truth_topic: robots.truth.clone(),
        anchors: None,
        robots: None,
        sim: sim_tx,
    };
    let robots = Robots {
        out,
        root,
        topics: robots,
        missions: Roster::new(MAX_ROBOTS),
        driven: Roster::new(MAX_ROBOTS),
        driven_dirty: false,
        sim: sim_rx,
    };
    tokio::join!(
        world.run(layers, deltas, cancel.clone()),
        robots.run(truth, estimate, mission, cancel),
    );
}
