//! The world loop: the map server's layers (published, deltas, fetched), the anchors
//! and the sim's robots.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::Ordering;
use std::sync::Arc;

use foxglove::messages::{Grid, Timestamp};
use roam_proto::keys;
use roam_proto::layer_delta::{LayerDelta, MAX_DELTA_BYTES};
use roam_proto::map::{Layer, LayerList};
use roam_proto::sim::{GroundTruth, NamedPoint, SimControl, SimStatus};
use tokio::sync::watch;
use tokio::time::MissedTickBehavior;
use tokio_util::sync::CancellationToken;
use zenoh::sample::Sample;
use zenoh::Session;

use crate::convert;
use crate::output::{Outputs, Topic};
use crate::roster::MAX_ROBOTS;
use crate::wire::{self, clipped, shown};

use super::limits::{
    MAX_LAYERS, MAX_LAYER_BYTES_KEPT, MAX_LAYER_BYTES_SHOWN, MAX_LAYER_CELLS, QUERY_TIMEOUT,
    REFRESH_PERIOD,
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
        let mut refresh = tokio::time::interval(REFRESH_PERIOD);
        refresh.set_missed_tick_behavior(MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = layers.recv_async() => match sample {
                    Ok(sample) => self.on_layer(&sample),
                    Err(_) => break,
                },
                sample = deltas.recv_async() => match sample {
                    Ok(sample) => {
                        tokio::select! {
                            _ = cancel.cancelled() => break,
                            _ = self.on_delta(&sample) => {}
                        }
                    }
                    Err(_) => break,
                },
                _ = refresh.tick() => {
                    tokio::select! {
                        _ = cancel.cancelled() => break,
                        _ = self.refresh() => {}
                    }
                }
            }
        }
    }

    fn on_layer(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let Some(layer) = decode_sample::<Layer>(&self.out, sample, wire::MAX_LAYER_BYTES) else {
            return;
        };
        if key != keys::map_layer(&self.root, &layer.name) {
            self.out.counters.dropped(
                key,
                &format!("a layer named \"{}\" on another key", shown(&layer.name)),
            );
            return;
        }
        self.show_layer(layer, true);
    }

    /// A delta of a layer shown: applied to it when it is the delta's base version;
    /// ignored when the view already shows the delta's version or a later one (a delta
    /// that arrived late; a map server restarted with lower versions is caught up by the
    /// refresh); otherwise (the view missed a delta, shows nothing of the layer, or did
    /// not keep a layer that large) the whole layer is fetched.
    async fn on_delta(&mut self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let Some(delta) = decode_sample::<LayerDelta>(&self.out, sample, MAX_DELTA_BYTES) else {
            return;
        };
        if key != keys::map_delta(&self.root, &delta.name) {
            return self.out.counters.dropped(
                key,
                &format!("a delta of \"{}\" on another key", shown(&delta.name)),
            );
        }
        let Some(held) = self.layers.get(&delta.name) else {
            return self.fetch(&delta.name).await;
        };
        if held.version >= delta.version {
            return;
        }
        let Some(mut layer) = held.layer.clone() else {
            return self.fetch(&delta.name).await;
        };
        match delta.apply(&mut layer) {
            Ok(()) => self.show_layer(layer, true),
            Err(e) => {
                tracing::debug!(layer = %delta.name, "roam view: {e}");
                self.fetch(&delta.name).await;
            }
        }
    }

    /// Fetches layer `name` whole and shows it when its version is not the one shown.
    async fn fetch(&mut self, name: &str) {
        // A name that is not a key segment would make a key of its own (a wildcard, say).
        let index = keys::map_index(&self.root);
        if keys::check_name("layer", name).is_err() {
            let reason = format!("a layer named \"{}\"", shown(name));
            return self.out.counters.dropped(&index, &reason);
        }
        let key = keys::map_layer(&self.root, name);
        let fetched = wire::query::<Layer, Layer>(
            &self.session,
            &key,
            None,
            wire::MAX_LAYER_BYTES,
            QUERY_TIMEOUT,
        )
        .await;
        match fetched {
            Ok(layer) if layer.name == name => self.show_layer(layer, false),
            Ok(layer) => self
                .out
                .counters
                .dropped(&key, &format!("a layer named \"{}\"", shown(&layer.name))),
            Err(e) => self.out.counters.unread(&key, &e),
        }
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

    /// Fetches every layer not shown at its current version, and the sim's status.
    async fn refresh(&mut self) {
        let index = keys::map_index(&self.root);
        match wire::query::<Layer, LayerList>(
            &self.session,
            &index,
            None,
            wire::MAX_LAYER_LIST_BYTES,
            QUERY_TIMEOUT,
        )
        .await
        {
            Ok(list) => {
                for info in list.layers.iter().take(MAX_LAYERS) {
                    // A name that is not a key segment would make a key of its own
                    // (a wildcard, say) for the query below.
                    if keys::check_name("layer", &info.name).is_err() {
                        let reason = format!("a layer named \"{}\"", shown(&info.name));
                        self.out.counters.dropped(&index, &reason);
                        continue;
                    }
                    let version = self.layers.get(&info.name).map(|s| s.version);
                    if version == Some(info.version) {
                        continue;
                    }
                    self.fetch(&info.name).await;
                }
            }
            Err(e) => tracing::debug!("roam view: no layer index yet: {}", clipped(&e.to_string())),
        }
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
