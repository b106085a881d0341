//! The world loop: the map server's layers (followed by `roam_runtime::layer_follow`:
//! published, deltas, fetched), the anchors and the sim's robots.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::Ordering;
use std::sync::Arc;

use foxglove::messages::{Grid, Timestamp};
use roam_proto::keys;
use roam_proto::map::{Layer, LayerList};
use roam_proto::sim::{GroundTruth, NamedPoint, SimControl, SimStatus};
use roam_proto::Message;
use roam_runtime::layer_follow::{follow_layers, LayerSink};
use tokio::sync::watch;
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;
use zenoh::Session;

use crate::convert;
use crate::output::{Outputs, Topic};
use crate::roster::MAX_ROBOTS;
use crate::wire::{self, clipped, shown, WireError};

use super::limits::{
    MAX_LAYERS, MAX_LAYER_BYTES_KEPT, MAX_LAYER_BYTES_SHOWN, MAX_LAYER_CELLS, QUERY_TIMEOUT,
};
use super::samples::{decode_sample, Ring, SimRobots};

/// A layer shown: its topic, its version, the layer itself when it is small enough to
/// keep for deltas ([`MAX_LAYER_BYTES_KEPT`]) and the bytes its cells take.
pub(super) struct Shown {
    topic: Topic,
    version: u64,
    layer: Option<Layer>,
    bytes: usize,
}

/// The map layers, the anchors and the sim's robot list.
pub(super) struct World {
    pub(super) out: Arc<Outputs>,
    pub(super) root: String,
    pub(super) session: Session,
    pub(super) layers: BTreeMap<String, Shown>,
    /// The bytes of cells of every layer shown.
    pub(super) layer_bytes: usize,
    pub(super) anchors_topic: Topic,
    pub(super) truth_topic: Topic,
    pub(super) anchors: Option<Vec<NamedPoint>>,
    pub(super) robots: Option<Vec<NamedPoint>>,
    pub(super) sim: watch::Sender<SimRobots>,
}

impl World {
    pub(super) async fn run(mut self, layers: Ring, deltas: Ring, cancel: CancellationToken) {
        let root = self.root.clone();
        follow_layers(&mut self, &root, layers, deltas, cancel).await;
    }

    /// Shows a layer unless this version is already shown. A published layer is always
    /// news; a fetched one only when its version differs from the one shown.
    fn show_layer(&mut self, layer: Layer, published: bool) {
        let key = keys::map_layer(&self.root, &layer.name);
        let shown_before = self.layers.get(&layer.name);
        if let Some(before) = shown_before {
            if before.version == layer.version && !published {
                return;
            }
        }
        let refusal = if keys::check_name("layer", &layer.name).is_err() {
            Some(format!(
                "the layer name \"{}\" is not a key segment",
                shown(&layer.name)
            ))
        } else if shown_before.is_none() && self.layers.len() >= MAX_LAYERS {
            Some(format!(
                "more than {MAX_LAYERS} layers; this one is not shown"
            ))
        } else if layer.meta.cell_count() > MAX_LAYER_CELLS {
            Some(format!(
                "{} cells; a layer is shown up to {MAX_LAYER_CELLS} (max_layer_cells)",
                layer.meta.cell_count()
            ))
        } else {
            None
        };
        let bytes = layer.cells.len() * layer.cells.dtype().size();
        let others = self.layer_bytes - shown_before.map_or(0, |s| s.bytes);
        let refusal = refusal.or_else(|| {
            (others + bytes > MAX_LAYER_BYTES_SHOWN).then(|| {
                format!("the layers shown would hold more than {MAX_LAYER_BYTES_SHOWN} bytes")
            })
        });
        if let Some(reason) = refusal {
            return self.out.counters.dropped(&key, &reason);
        }
        let grid = match convert::grid(&layer, Timestamp::now()) {
            Ok(grid) => grid,
            Err(e) => return self.out.counters.dropped(&key, &e),
        };
        let out = &self.out;
        tracing::debug!(layer = %layer.name, version = layer.version, "roam view: layer shown");
        let topic = match self.layers.remove(&layer.name) {
            Some(before) => before.topic,
            None => out.topic::<Grid>(&convert::layer_topic(&layer.name), true),
        };
        out.log(&topic, &grid);
        self.layers.insert(
            layer.name.clone(),
            Shown {
                topic,
                version: layer.version,
                layer: (bytes <= MAX_LAYER_BYTES_KEPT).then_some(layer),
                bytes,
            },
        );
        self.layer_bytes = others + bytes;
    }

    /// Asks the sim for its anchors and robots (each refresh, after the layers).
    async fn refresh_sim(&mut self) {
        match wire::query::<SimControl, SimStatus>(
            &self.session,
            &keys::sim_control(&self.root),
            Some(&SimControl::Status),
            wire::MAX_SIM_STATUS_BYTES,
            QUERY_TIMEOUT,
        )
        .await
        {
            Ok(status) => self.show_status(status),
            Err(e) => tracing::debug!("roam view: no sim status yet: {}", clipped(&e.to_string())),
        }
    }

    fn show_status(&mut self, status: SimStatus) {
        let now = Timestamp::now();
        if self.robots.as_ref() != Some(&status.robots) {
            let key = keys::sim_control(&self.root);
            let mut named = BTreeSet::new();
            for robot in &status.robots {
                if keys::check_name("robot", &robot.name).is_err() {
                    let reason = format!("the sim names a robot \"{}\"", shown(&robot.name));
                    self.out.counters.dropped(&key, &reason);
                } else if named.len() < MAX_ROBOTS {
                    named.insert(robot.name.clone());
                }
            }
            self.out
                .counters
                .sim_robots
                .store(named.len(), Ordering::Relaxed);
            // The robots where the sim has them: seen even when the sim is paused (it then
            // publishes no true positions).
            for robot in status.robots.iter().filter(|r| named.contains(&r.name)) {
                let truth = GroundTruth {
                    robot: robot.name.clone(),
                    step: status.step,
                    time_s: status.time_s,
                    at: robot.at,
                };
                self.out
                    .log(&self.truth_topic, &convert::truth(&truth, now));
            }
            self.sim.send_replace(Arc::new(named));
            self.robots = Some(status.robots);
        }
        if self.anchors.as_ref() != Some(&status.anchors) {
            self.out
                .log(&self.anchors_topic, &convert::anchors(&status.anchors, now));
            self.anchors = Some(status.anchors);
        }
    }
}

impl LayerSink for World {
    type Error = WireError;
    const MAX_LAYER_BYTES: usize = wire::MAX_LAYER_BYTES;
    const MAX_LAYERS: usize = MAX_LAYERS;

    fn follows(&self, _name: &str) -> bool {
        true
    }

    fn held(&self, name: &str) -> Option<u64> {
        self.layers.get(name).map(|s| s.version)
    }

    fn take_kept(&mut self, name: &str) -> Option<Layer> {
        self.layers.get_mut(name)?.layer.take()
    }

    async fn show(&mut self, layer: Layer, published: bool) {
        self.show_layer(layer, published);
    }

    fn decode<T: Message>(&self, sample: &Sample, max: usize) -> Option<T> {
        decode_sample(&self.out, sample, max)
    }

    fn refuse(&self, key: &str, reason: &str) {
        self.out.counters.dropped(key, &reason);
    }

    fn unread(&self, key: &str, error: &WireError) {
        self.out.counters.unread(key, error);
    }

    async fn query_layer(&self, key: &str) -> Result<Layer, WireError> {
        let max = wire::MAX_LAYER_BYTES;
        wire::query::<Layer, Layer>(&self.session, key, None, max, QUERY_TIMEOUT).await
    }

    async fn query_index(&self, key: &str) -> Result<LayerList, WireError> {
        let max = wire::MAX_LAYER_LIST_BYTES;
        wire::query::<Layer, LayerList>(&self.session, key, None, max, QUERY_TIMEOUT).await
    }

    async fn refreshed(&mut self) {
        self.refresh_sim().await;
    }
}
