//! The map server on Zenoh: a thin adapter that turns queries into calls on the
//! [`LayerStore`] and publishes each changed layer.
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/map/layer/<name>` | queryable + publication of whole layers | [`Layer`](roam_proto::map::Layer) |
//! | `<root>/map/delta/<name>` | publication of `set_cells` changes | [`LayerDelta`](roam_proto::layer_delta::LayerDelta) |
//! | `<root>/map/update/<name>` | queryable | `LayerUpdate` → `UpdateAck` |
//! | `<root>/map/delete/<name>` | queryable | `DeleteLayer` → `LayerDeleted` |
//! | `<root>/map/layers` | queryable | → `LayerList` |
//! | `<root>/map/load` | queryable | `LoadMap` → `LayerList` |

use roam_runtime::Delivery;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard};

use roam_proto::map::{DeleteLayer, Layer, LayerList, LayerUpdate, LoadMap, MAX_WIRE_CELL_WRITES};
use roam_proto::{encode, keys, ErrorCode, ErrorReply};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::{reply, PayloadBudget, Service, ServiceError};
use tokio_util::sync::CancellationToken;
use zenoh::bytes::ZBytes;
use zenoh::key_expr::KeyExpr;
use zenoh::query::Query;
use zenoh::Session;

use crate::config::MapServerConfig;
use crate::map_file::{self, MapFileError};
use crate::persist::{DataDir, PersistError};
use crate::store::{DerivedParams, LayerStore, Publication, OCCUPANCY};
use roam_world::load_dirs::LoadDirs;

/// The service name in liveliness tokens and logs.
pub const SERVICE_NAME: &str = "map-server";

/// Why the map server could not start or stopped badly.
#[derive(Debug, thiserror::Error)]
pub enum MapServerError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error("the configured map could not be loaded: {0}")]
    Map(#[from] MapFileError),
    #[error("the data directory could not be used: {0}")]
    Persist(#[from] PersistError),
    #[error("the initial map could not be stored: {0}")]
    Store(String),
    #[error("invalid config: {0}")]
    Config(String),
}

/// Largest load request, bytes: a file name.
pub const MAX_LOAD_REQUEST_BYTES: usize = 64 * 1024;

/// What the query handlers share.
struct MapServerShared {
    root: String,
    store: Mutex<LayerStore>,
    /// Each layer encoded once per version, shared by gets and publications.
    encoded: Mutex<HashMap<String, (u64, ZBytes)>>,
    robot_radius_override: Option<f64>,
    load_dirs: LoadDirs,
    /// Refused loads and updates, logged a few per source and window.
    warnings: WarnLimiter,
    session: Session,
}

impl MapServerShared {
    fn store(&self) -> MutexGuard<'_, LayerStore> {
        // A panic while holding the lock would be a bug; the store is still consistent
        // because changes are staged and installed at the end.
        roam_runtime::lock(&self.store)
    }

    fn cache(&self) -> MutexGuard<'_, HashMap<String, (u64, ZBytes)>> {
        roam_runtime::lock(&self.encoded)
    }

    /// The encoded layer (as the store holds it now), from the cache when its version
    /// is current.
    fn encoded(&self, name: &str) -> Option<ZBytes> {
        let layer = self.store().get_shared(name)?;
        Some(self.encode(&layer))
    }

    /// Encodes a layer taken from the store, outside the store's lock: a large layer
    /// takes milliseconds to encode, during which updates and `map/layers` go on.
    fn encode(&self, layer: &Layer) -> ZBytes {
        if let Some((version, bytes)) = self.cache().get(&layer.name) {
            if *version == layer.version {
                return bytes.clone();
            }
        }
        let bytes = ZBytes::from(encode(layer));
        let mut cache = self.cache();
        let newer = cache
            .get(&layer.name)
            .is_some_and(|(version, _)| *version > layer.version);
        if !newer {
            cache.insert(layer.name.clone(), (layer.version, bytes.clone()));
        }
        bytes
    }

    /// Publishes each changed layer: a delta on `map/delta/<name>`, or the whole layer
    /// (as the store holds it now) on `map/layer/<name>`.
    async fn publish(&self, publications: &[Publication]) {
        for publication in publications {
            let (key, bytes) = match publication {
                Publication::Whole(name) => {
                    let Some(bytes) = self.encoded(name) else {
                        continue;
                    };
                    (keys::map_layer(&self.root, name), bytes)
                }
                Publication::Delta(delta) => (
                    keys::map_delta(&self.root, &delta.name),
                    ZBytes::from(encode(delta)),
                ),
            };
            // A layer version is delivered: subscribers plan and drive on it.
            roam_runtime::publish_bytes(&self.session, &key, bytes, Delivery::Reliable).await;
        }
    }

    /// Publishes whole layers.
    async fn publish_whole(&self, names: &[String]) {
        let whole: Vec<Publication> = names.iter().cloned().map(Publication::Whole).collect();
        self.publish(&whole).await;
    }
}

/// Builds the store: restores persisted layers, or loads the configured map (the
/// built-in world when none is configured).
pub fn open_store(config: &MapServerConfig) -> Result<LayerStore, MapServerError> {
    if !(config.heuristic_compression > 0.0 && config.heuristic_compression <= 1.0) {
        return Err(MapServerError::Config(format!(
            "heuristic_compression must be in (0, 1], got {}",
            config.heuristic_compression
        )));
    }
    if config.limits.max_cells_per_update > MAX_WIRE_CELL_WRITES as u64 {
        return Err(MapServerError::Config(format!(
            "limits.max_cells_per_update is {}; at most {MAX_WIRE_CELL_WRITES} cells travel in one update",
            config.limits.max_cells_per_update
        )));
    }
    let data = config
        .data_dir
        .as_deref()
        .map(|dir| DataDir::open(dir, config.limits.max_layer_cells))
        .transpose()?;
    let mut derived = DerivedParams {
        heuristic_compression: config.heuristic_compression,
        lethal_threshold: config.lethal_threshold,
        ..DerivedParams::default()
    };
    if let Some(r) = config.robot_radius_m {
        derived.robot_radius_m = r;
    }
    let mut store = LayerStore::new(config.limits, derived, data);
    let restored = store
        .restore(config.robot_radius_m.is_some())
        .map_err(|e| MapServerError::Store(e.to_string()))?;
    if restored.found && restored.lost_sources.is_empty() {
        tracing::info!(
            layers = store.names().count(),
            "restored the layers and their versions from the data dir"
        );
        return Ok(store);
    }
    let content = configured_map(config)?;
    let radius_follows_map = restored.lost_sources.contains(&OCCUPANCY) || !restored.found;
    if let (None, Some(r), true) = (
        config.robot_radius_m,
        content.robot_radius_m,
        radius_follows_map,
    ) {
        store.set_robot_radius(r);
    }
    if restored.found {
        let map_name = config.map.as_ref().map_or_else(
            || roam_world::scenario::BUILTIN_NAME.to_owned(),
            |p| p.display().to_string(),
        );
        store
            .reload_lost_sources(
                content.occupancy,
                content.information,
                &restored.lost_sources,
                &map_name,
            )
            .map_err(|e| MapServerError::Store(e.to_string()))?;
        if restored.lost_sources.contains(&OCCUPANCY) || store.world().is_none() {
            store
                .set_world(content.world)
                .map_err(|e| MapServerError::Store(e.to_string()))?;
        }
        return Ok(store);
    }
    store
        .load_map(content.occupancy, content.information, None)
        .map_err(|e| MapServerError::Store(e.to_string()))?;
    store
        .set_world(content.world)
        .map_err(|e| MapServerError::Store(e.to_string()))?;
    Ok(store)
}

/// The configured map, or the built-in world when none is configured.
fn configured_map(config: &MapServerConfig) -> Result<map_file::MapContent, MapServerError> {
    Ok(match &config.map {
        Some(path) => map_file::read(path, config.limits.max_layer_cells)?,
        None => map_file::builtin(config.limits.max_layer_cells)?,
    })
}

/// Runs the map server until `cancel` is cancelled.
pub async fn run(
    config: MapServerConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), MapServerError> {
    let store = open_store(&config)?;
    let load_dirs =
        LoadDirs::new(&config.load_dirs).map_err(|e| MapServerError::Config(e.to_string()))?;
    let mut service = Service::start(SERVICE_NAME, &config.service, zenoh_config, cancel).await?;
    let state = Arc::new(MapServerShared {
        root: config.service.root.clone(),
        store: Mutex::new(store),
        encoded: Mutex::new(HashMap::new()),
        robot_radius_override: config.robot_radius_m,
        load_dirs,
        warnings: WarnLimiter::new(),
        session: service.session().clone(),
    });
    let root = config.service.root.as_str();
    let layer_q = service
        .declare_queryable(&keys::map_layer_any(root))
        .await?;
    let update_q = service
        .declare_queryable(&keys::map_update_any(root))
        .await?;
    let delete_q = service
        .declare_queryable(&keys::map_delete_any(root))
        .await?;
    let index_q = service.declare_queryable(&keys::map_index(root)).await?;
    let load_q = service.declare_queryable(&keys::map_load(root)).await?;

    let all: Vec<String> = state.store().names().map(str::to_owned).collect();
    state.publish_whole(&all).await;

    service.serve(layer_q, state.clone(), |s, q| async move {
        answer_layer(&s, &q).await
    });
    // One maximal update in work at a time (smaller ones share the room): decoding,
    // checking, storing and publishing a layer costs a few times its payload.
    let budget = PayloadBudget::new(config.limits.max_request_bytes as usize);
    service.serve_within(update_q, Some(budget), state.clone(), |s, q| async move {
        answer_update(s, &q).await
    });
    service.serve(delete_q, state.clone(), |s, q| async move {
        answer_delete(s, &q).await
    });
    service.serve(index_q, state.clone(), |s, q| async move {
        let list = s.store().list();
        reply::send(&q, &list).await;
    });
    service.serve(load_q, state.clone(), |s, q| async move {
        answer_load(s, &q).await
    });
    service.announce().await?;

    service.run_until_stopped().await?;
    Ok(())
}

/// Answers a layer `get`: every layer whose key matches the query's key expression,
/// all taken from the store at one moment, so a wildcard `get` never mixes a new
/// `occupancy` with an old `inflated`.
async fn answer_layer(state: &MapServerShared, query: &Query) {
    let (names, matching): (Vec<String>, Vec<_>) = {
        let store = state.store();
        let names: Vec<String> = store.names().map(str::to_owned).collect();
        let matching = names
            .iter()
            .filter_map(|name| {
                let key = KeyExpr::try_from(keys::map_layer(&state.root, name)).ok()?;
                if !query.key_expr().intersects(&key) {
                    return None;
                }
                Some((key, store.get_shared(name)?))
            })
            .collect();
        (names, matching)
    };
    if matching.is_empty() {
        let error = ErrorReply::new(
            ErrorCode::NotFound,
            format!(
                "no layer matches '{}'; the map server holds: {}",
                roam_proto::excerpt(query.key_expr().as_str()),
                names.join(", ")
            ),
        );
        reply::send_error(query, &error).await;
        return;
    }
    for (key, layer) in matching {
        let bytes = state.encode(&layer);
        if let Err(e) = query.reply(key.clone(), bytes).await {
            tracing::warn!(%key, "reply failed: {e}");
        }
    }
}

/// The layer named by the last segment of a concrete key, e.g. `roam/map/update/peb`.
fn layer_name_of(query: &Query) -> Result<String, ErrorReply> {
    let key = query.key_expr().as_str();
    let name = key.rsplit('/').next().unwrap_or_default();
    keys::check_name("layer name", name).map_err(|e| {
        ErrorReply::new(
            ErrorCode::InvalidRequest,
            format!("{e}; name one layer in the key, e.g. <root>/map/update/occupancy"),
        )
    })?;
    Ok(name.to_owned())
}

async fn answer_update(state: Arc<MapServerShared>, query: &Query) {
    let max = state.store().limits().max_request_bytes as usize;
    let request = layer_name_of(query)
        .and_then(|name| Ok((name, reply::decode_request::<LayerUpdate>(query, max)?)));
    let (name, update) = match request {
        Ok(r) => r,
        Err(e) => return reply::send_error(query, &e).await,
    };
    let worker = state.clone();
    let outcome = tokio::task::spawn_blocking(move || {
        worker
            .store()
            .apply(&name, &update)
            .map_err(|e| e.to_reply())
    })
    .await;
    match outcome {
        Ok(Ok((ack, changed))) => {
            reply::send(query, &ack).await;
            state.publish(&changed).await;
        }
        Ok(Err(error)) => reply::send_error(query, &error).await,
        Err(e) => {
            reply::send_error(
                query,
                &ErrorReply::new(ErrorCode::Internal, format!("the update task failed: {e}")),
            )
            .await
        }
    }
}

async fn answer_delete(state: Arc<MapServerShared>, query: &Query) {
    let max = state.store().limits().max_request_bytes as usize;
    let request = layer_name_of(query)
        .and_then(|name| Ok((name, reply::decode_request::<DeleteLayer>(query, max)?)));
    let (name, request) = match request {
        Ok(r) => r,
        Err(e) => return reply::send_error(query, &e).await,
    };
    let worker = state.clone();
    let outcome = tokio::task::spawn_blocking(move || {
        let deleted = worker
            .store()
            .delete(&name, request.base_version)
            .map_err(|e| e.to_reply())?;
        worker.cache().remove(&name);
        Ok(deleted)
    })
    .await;
    match outcome {
        Ok(result) => reply::send_result(query, result).await,
        Err(e) => {
            reply::send_error(
                query,
                &ErrorReply::new(ErrorCode::Internal, format!("the delete task failed: {e}")),
            )
            .await
        }
    }
}

async fn answer_load(state: Arc<MapServerShared>, query: &Query) {
    let request = match reply::decode_request::<LoadMap>(query, MAX_LOAD_REQUEST_BYTES) {
        Ok(r) => r,
        Err(e) => return reply::send_error(query, &e).await,
    };
    let worker = state.clone();
    let outcome = tokio::task::spawn_blocking(move || load(&worker, &request)).await;
    match outcome {
        Ok(Ok((list, changed))) => {
            reply::send(query, &list).await;
            state.publish_whole(&changed).await;
        }
        Ok(Err(refused)) => {
            // The log keeps the server's paths; the peer's reply does not.
            let detail = &refused.detail;
            roam_runtime::limited_warn!(state.warnings, "load", %detail, "refused a map load");
            reply::send_error(query, &refused.reply).await
        }
        Err(e) => {
            reply::send_error(
                query,
                &ErrorReply::new(ErrorCode::Internal, format!("the load task failed: {e}")),
            )
            .await
        }
    }
}

/// A refused load: the reply for the peer, and the detail for the server's log.
struct LoadRefusal {
    reply: ErrorReply,
    detail: String,
}

impl From<ErrorReply> for LoadRefusal {
    fn from(reply: ErrorReply) -> Self {
        LoadRefusal {
            detail: reply.to_string(),
            reply,
        }
    }
}

fn load(
    state: &MapServerShared,
    request: &LoadMap,
) -> Result<(LayerList, Vec<String>), LoadRefusal> {
    let max_cells = state.store().limits().max_layer_cells;
    let content =
        map_file::read_requested(&request.path, &state.load_dirs, max_cells).map_err(|e| {
            LoadRefusal {
                reply: e.to_reply(&request.path, &state.load_dirs),
                detail: e.to_string(),
            }
        })?;
    let mut store = state.store();
    if let (None, Some(r)) = (state.robot_radius_override, content.robot_radius_m) {
        store.set_robot_radius(r);
    }
    let changed = store
        .load_map(content.occupancy, content.information, request.base_version)
        .map_err(|e| e.to_reply())?;
    store.set_world(content.world).map_err(|e| e.to_reply())?;
    Ok((store.list(), changed))
}
