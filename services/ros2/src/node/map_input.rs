//! ROS 2 → roam: `--ros2-map /map` takes the map server's occupancy from a ROS 2
//! publisher of nav_msgs/msg/OccupancyGrid (Nav2's map_server), one new occupancy
//! version per map received.
//!
//! The subscription is rmw_zenoh's transient-local one: a zenoh-ext AdvancedSubscriber
//! on the topic's key that detects late publishers and asks their cache for the last
//! map (history depth 1), with the `MS` liveliness token. Each map is checked before it
//! is read: the payload against `max_layer_cells` bytes, the header's width × height
//! against `max_layer_cells` (a 10⁹-cell map is refused from its first 80 bytes), the
//! attachment (rmw_zenoh drops samples without one, and so does roam), then the cells.
//! A map published on the topic with another type or type hash never matches the key;
//! a second, plain subscriber on the topic's other keys sees it and logs why it is
//! refused. Accepted maps go to the map server as a `replace` of `occupancy` on roam's
//! own update key, based on the version it has (retried once when stale): the map
//! server's own checks and limits apply, and its refusals are logged here.

use std::sync::Arc;
use std::time::Duration;

use roam_proto::map::{LayerChange, LayerList, LayerUpdate, UpdateAck};
use roam_proto::{keys, ErrorCode};
use roam_runtime::{ClientError, Requester, Service};
use serde::Deserialize;
use zenoh::sample::Sample;
use zenoh_ext::{AdvancedSubscriberBuilderExt, HistoryConfig};

use super::config::Ros2Config;
use super::error::Ros2Error;
use super::output::Output;
use crate::attachment::Attachment;
use crate::convert;
use crate::msg::{Header, MapMetaData, OccupancyGrid};
use crate::names::{EntityKind, Qos};
use crate::types;

/// Bytes a received map may take beyond its cells (header, frame id, sizes).
const ENVELOPE_BYTES: usize = 64 * 1024;
const UPDATE_TIMEOUT: Duration = Duration::from_secs(30);

/// The first fields of an OccupancyGrid: enough to know its size before reading cells.
#[derive(Debug, Deserialize)]
struct GridHead {
    #[allow(dead_code)]
    header: Header,
    info: MapMetaData,
}

pub(crate) async fn declare(
    service: &Service,
    out: Arc<Output>,
    config: &Ros2Config,
    topic: &str,
) -> Result<(), Ros2Error> {
    let endpoint = out
        .endpoint(
            EntityKind::Subscription,
            topic,
            types::OCCUPANCY_GRID,
            Qos::LATCHED,
        )
        .map_err(|e| Ros2Error::Declare {
            what: "map subscription",
            key: topic.to_owned(),
            reason: e.to_string(),
        })?;
    let session = out.session().clone();
    let declare_error = |what: &'static str, key: &str, e: zenoh::Error| Ros2Error::Declare {
        what,
        key: key.to_owned(),
        reason: e.to_string(),
    };
    let maps = session
        .declare_subscriber(endpoint.key.clone())
        // As rmw_zenoh's `ignore_local_publications`: never roam's own samples.
        .allowed_origin(zenoh::sample::Locality::Remote)
        .history(
            HistoryConfig::default()
                .detect_late_publishers()
                .max_samples(1),
        )
        .subscriber_detection()
        .await
        .map_err(|e| declare_error("map subscriber", &endpoint.key, e))?;
    // Everything else published under the topic's name: other types, other hashes.
    let name = endpoint.qualified_name.trim_matches('/').to_owned();
    let others_key = format!("{}/{name}/*/*", out.node().domain);
    let others = session
        .declare_subscriber(others_key.clone())
        .await
        .map_err(|e| declare_error("subscriber", &others_key, e))?;
    let token = out.token(&endpoint.token).await?;
    let input = MapInput {
        out,
        requester: Requester::new(session, UPDATE_TIMEOUT),
        root: config.service.root.clone(),
        max_cells: config.max_layer_cells,
        key: endpoint.key.clone(),
        topic: endpoint.qualified_name.clone(),
    };
    let cancel = service.cancel_token();
    service.spawn(async move {
        let _token = token;
        loop {
            tokio::select! {
                biased;
                _ = cancel.cancelled() => break,
                sample = maps.recv_async() => match sample {
                    Ok(sample) => input.on_map(&sample).await,
                    Err(_) => break,
                },
                sample = others.recv_async() => match sample {
                    Ok(sample) => input.on_other(&sample),
                    Err(_) => break,
                },
            }
        }
    });
    tracing::info!(topic, key = %endpoint.key, "roam ros2: taking the occupancy map from ROS 2");
    Ok(())
}

struct MapInput {
    out: Arc<Output>,
    requester: Requester,
    root: String,
    max_cells: u64,
    key: String,
    topic: String,
}

impl MapInput {
    fn on_other(&self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        if key == self.key {
            return;
        }
        let (ty, hash) = key
            .rsplit_once('/')
            .map(|(rest, hash)| (rest.rsplit('/').next().unwrap_or(""), hash))
            .unwrap_or(("", ""));
        self.out.refuse(
            key,
            &format!(
                "a sample on {} of type '{}' with hash '{}'; roam takes nav_msgs::msg::dds_::OccupancyGrid_ with {} here",
                self.topic,
                roam_proto::excerpt::excerpt_n(ty, 64),
                roam_proto::excerpt::excerpt_n(hash, 80),
                self.key.rsplit('/').next().unwrap_or("")
            ),
        );
    }

    /// Reads a map, or says why not.
    fn read(&self, sample: &Sample) -> Result<OccupancyGrid, String> {
        match sample.attachment() {
            Some(bytes) => Attachment::parse(&bytes.to_bytes()).map_err(|e| e.to_string())?,
            None => {
                return Err(
                    "a sample without rmw_zenoh's attachment (ROS 2 drops those too)".into(),
                )
            }
        };
        let payload = sample.payload().to_bytes();
        let max = usize::try_from(self.max_cells)
            .unwrap_or(usize::MAX)
            .saturating_add(ENVELOPE_BYTES);
        if payload.len() > max {
            return Err(format!(
                "{} bytes; a map is read up to {max} bytes ({} cells, max_layer_cells)",
                payload.len(),
                self.max_cells
            ));
        }
        let head: GridHead =
            crate::cdr::decode_prefix(&payload, "OccupancyGrid").map_err(|e| e.to_string())?;
        convert::check_grid_size(&head.info, self.max_cells).map_err(|e| e.to_string())?;
        crate::cdr::decode::<OccupancyGrid>(&payload, "OccupancyGrid", max)
            .map_err(|e| e.to_string())
    }

    async fn on_map(&self, sample: &Sample) {
        let grid = match self.read(sample) {
            Ok(grid) => grid,
            Err(reason) => return self.out.refuse(&self.key, &reason),
        };
        let (meta, cells) = match convert::grid_to_occupancy(&grid, self.max_cells) {
            Ok(layer) => layer,
            Err(e) => return self.out.refuse(&self.key, &e.to_string()),
        };
        for attempt in 0..2 {
            let base = match self.occupancy_version().await {
                Ok(v) => v,
                Err(e) => {
                    return self
                        .out
                        .refuse(&self.key, &format!("the map server's layers: {e}"))
                }
            };
            let update = LayerUpdate {
                base_version: base,
                change: LayerChange::Replace {
                    meta,
                    cells: cells.clone(),
                },
                world: None,
            };
            let key = keys::map_update(&self.root, "occupancy");
            match self
                .requester
                .request::<LayerUpdate, UpdateAck>(&key, Some(&update))
                .await
            {
                Ok(ack) => {
                    tracing::info!(
                        topic = %self.topic,
                        width = meta.width,
                        height = meta.height,
                        version = ack.version,
                        "roam ros2: a ROS 2 map became occupancy version {}",
                        ack.version
                    );
                    return;
                }
                Err(ClientError::Refused(r))
                    if r.code == ErrorCode::StaleVersion && attempt == 0 =>
                {
                    continue
                }
                Err(e) => {
                    return self
                        .out
                        .refuse(&self.key, &format!("the map server refused the map: {e}"))
                }
            }
        }
    }

    async fn occupancy_version(&self) -> Result<u64, ClientError> {
        let list: LayerList = self
            .requester
            .request::<LayerList, LayerList>(&keys::map_index(&self.root), None)
            .await?;
        Ok(list
            .layers
            .iter()
            .find(|l| l.name == "occupancy")
            .map_or(0, |l| l.version))
    }
}
