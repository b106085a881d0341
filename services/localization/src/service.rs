//! The localization service on Zenoh: a thin adapter around [`Tracker`] (one estimate
//! per range scan) and the PEB fields.
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/robot/*/ranges` | subscription | `range_scan` (from the sim or a robot) |
//! | `<root>/sim/clock` | subscription | `sim_clock` (scan times are checked against it) |
//! | `<root>/robot/<id>/estimate` | publication, one per scan | `position_estimate` |
//! | `<root>/localization/peb` | queryable | `peb_query` → `peb_reply` |
//! | `<root>/map/update/peb` | query to the map server, once at start | `layer_update` (the PEB layer) |
//!
//! A scan names its anchors and their positions, so the estimate uses exactly the
//! anchors the robot heard; the sensing model (σ, d0, K, range) and the default
//! constellation for PEB queries come from the configured scenario. A scan's time is
//! checked against the sim clock the way the mapper checks an observation's
//! ([`roam_world::epoch`]): a scan stamped far ahead of the clock gives no estimate, so a
//! forged time never reaches the controller or the executive.

use roam_runtime::Delivery;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use roam_proto::cells::Cells;
use roam_proto::localization::{CrbCells, PebAt, PebQuery, PebReply, PebWhere};
use roam_proto::map::{GridMeta, LayerChange, LayerList, LayerUpdate, Origin, UpdateAck};
use roam_proto::sim::{NamedPoint, RangeScan, SimClock};
use roam_proto::{keys, ErrorCode, ErrorReply};
use roam_runtime::service_config::{ServiceConfig, UnknownFields};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::{limited_warn, reply, routing, Requester, Service, ServiceError};
use roam_world::epoch::Epochs;
use roam_world::scenario::load_or_builtin;
use roam_world::scenario::SensingSpec;
use serde::Deserialize;
use tokio_util::sync::CancellationToken;
use zenoh::query::Query;

use crate::field::{
    bounds_at, crb_field, peb_field, peb_gradient, GridRegion, DEFAULT_GRADIENT_STEP_M,
};
use crate::fim::FimOptions;
use crate::model::RangingModel;
use crate::tracker::Tracker;
use crate::LocalizationError;

pub const SERVICE_NAME: &str = "localization";
/// Robots whose last estimate is kept as the next prior.
pub use crate::tracker::MAX_ROBOTS;
/// Largest PEB query, bytes.
pub const MAX_REQUEST_BYTES: usize = 4 * 1024 * 1024;
/// Largest range scan decoded, bytes: a scan of [`MAX_ANCHORS`](crate::model::MAX_ANCHORS)
/// anchors at about 100 bytes each, with room.
pub const MAX_SCAN_BYTES: usize = 1024 * 1024;
/// Largest sim clock decoded, bytes (one is about 60).
const MAX_CLOCK_BYTES: usize = 1024;
/// The name of the layer the service publishes to the map server.
pub const PEB_LAYER: &str = "peb";

/// The localization service's config file (YAML).
///
/// ```yaml
/// root: roam
/// scenario: config/scenarios/es1.yaml   # sensing model and constellation; default: built-in world
/// variance_derivative: true             # include dσ²/dd in the Fisher information
/// publish_peb_layer: true               # send the PEB field over the map to the map server
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct LocalizationConfig {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    pub scenario: Option<PathBuf>,
    pub variance_derivative: bool,
    pub publish_peb_layer: bool,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for LocalizationConfig {
    fn default() -> Self {
        LocalizationConfig {
            service: ServiceConfig::default(),
            scenario: None,
            variance_derivative: true,
            publish_peb_layer: true,
            unknown: UnknownFields,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum LocalizationServiceError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error(transparent)]
    Scenario(#[from] roam_world::scenario::ScenarioError),
    #[error("the scenario's sensing model is unusable: {0}")]
    Model(#[from] LocalizationError),
}

/// What the localization service's subscribers and queryables share: the session,
/// the sensing model and constellation, and every robot's tracker.
struct LocalizationShared {
    root: String,
    session: zenoh::Session,
    sensing: SensingSpec,
    /// The configured constellation, for PEB queries without their own anchors.
    anchors: Vec<NamedPoint>,
    map: GridMeta,
    fim: FimOptions,
    /// Per-robot priors: the one estimation code path the batch episodes share.
    tracker: Mutex<Tracker>,
    /// Scan times against the sim clock.
    epochs: Mutex<Epochs>,
    /// Refused scans, logged a few per key and window.
    warnings: WarnLimiter,
    /// The world this service works on, sent with its layer updates.
    world: roam_proto::map::WorldId,
}

fn model_of(
    anchors: &[[f64; 2]],
    sensing: &SensingSpec,
) -> Result<RangingModel, LocalizationError> {
    RangingModel::from_spec(anchors, sensing)
}

fn error_reply(e: &LocalizationError) -> ErrorReply {
    let message = e.to_string();
    match e {
        LocalizationError::TooManyAnchors { count, max } => {
            ErrorReply::limit("max_anchors", *max as u64, *count as u64, message)
        }
        LocalizationError::TooManyPoints { count, max } => {
            ErrorReply::limit("max_points", *max as u64, *count as u64, message)
        }
        LocalizationError::TooManyRanges { count, max } => {
            ErrorReply::limit("max_ranges", *max as u64, *count as u64, message)
        }
        _ => ErrorReply::new(ErrorCode::InvalidRequest, message),
    }
}

/// Runs the localization service until `cancel` is cancelled.
pub async fn run(
    config: LocalizationConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), LocalizationServiceError> {
    let (_, scenario) = load_or_builtin(config.scenario.as_deref())?;
    let sensing = scenario.file.sensing;
    let anchors: Vec<NamedPoint> = scenario
        .file
        .anchors
        .iter()
        .map(|a| NamedPoint {
            name: a.name.clone(),
            at: a.at,
        })
        .collect();
    // Refuse a sensing model that cannot work before going live.
    model_of(&anchors.iter().map(|a| a.at).collect::<Vec<_>>(), &sensing)?;
    let mut service = Service::start(SERVICE_NAME, &config.service, zenoh_config, cancel).await?;
    let world = roam_world::world_id::of_scenario(&scenario);
    service.guard_world(world.clone());
    let fim = FimOptions {
        variance_derivative: config.variance_derivative,
        ..FimOptions::default()
    };
    let state = Arc::new(LocalizationShared {
        world: world.clone(),
        root: config.service.root.clone(),
        session: service.session().clone(),
        sensing,
        anchors,
        map: scenario.occupancy.meta,
        fim,
        tracker: Mutex::new(Tracker::new(sensing, fim)),
        epochs: Mutex::new(Epochs::default()),
        warnings: WarnLimiter::new(),
    });
    service
        .subscribe_with(
            &keys::sim_clock(&config.service.root),
            MAX_CLOCK_BYTES,
            state.clone(),
            |state: &Arc<LocalizationShared>, _key: &str, clock: SimClock| {
                roam_runtime::lock(&state.epochs).on_clock(clock.time_s)
            },
        )
        .await?;
    service
        .subscribe_with(
            &keys::robot_ranges_any(&config.service.root),
            MAX_SCAN_BYTES,
            state.clone(),
            |state: &Arc<LocalizationShared>, key: &str, scan: RangeScan| on_scan(state, key, scan),
        )
        .await?;
    let peb = service
        .declare_queryable(&keys::localization_peb(&config.service.root))
        .await?;
    service.serve(
        peb,
        state.clone(),
        |s, q| async move { answer_peb(s, q).await },
    );
    if config.publish_peb_layer {
        let (state, cancel) = (state.clone(), service.cancel_token());
        service.spawn(async move { publish_peb_layer(state, cancel).await });
    }
    service.announce().await?;
    service.run_until_stopped().await?;
    Ok(())
}

/// Estimates a robot's position from one scan ([`Tracker::on_scan`]) and publishes it on
/// the robot's key: the robot is the one the scan's key names ([`routing`]).
fn on_scan(state: &LocalizationShared, key: &str, scan: RangeScan) {
    let robot = match routing::robot_for(&state.root, key, &scan.robot) {
        Ok(robot) => robot,
        Err(e) => return limited_warn!(state.warnings, key, "ignoring a scan: {e}"),
    };
    let time = roam_runtime::lock(&state.epochs).observation_time(scan.time_s);
    let time = match time {
        Ok(t) => t,
        Err(e) => return limited_warn!(state.warnings, robot, %robot, "ignoring a scan: {e}"),
    };
    roam_runtime::lock(&state.epochs).accepted(time);
    let message = match roam_runtime::lock(&state.tracker).on_scan(&scan) {
        Ok(m) => m,
        Err(e) => return limited_warn!(state.warnings, robot, %robot, "ignoring a scan: {e}"),
    };
    let key = keys::robot_estimate(&state.root, robot);
    // The next scan's estimate supersedes this one.
    roam_runtime::publish_wait(&state.session, &key, &message, Delivery::Latest);
}

async fn answer_peb(state: Arc<LocalizationShared>, query: Query) {
    let request = match reply::decode_request::<PebQuery>(&query, MAX_REQUEST_BYTES) {
        Ok(r) => r,
        Err(e) => return reply::send_error(&query, &e).await,
    };
    let result = tokio::task::spawn_blocking(move || peb_reply(&state, &request))
        .await
        .unwrap_or_else(|e| {
            Err(ErrorReply::new(
                ErrorCode::Internal,
                format!("the PEB task failed: {e}"),
            ))
        });
    reply::send_result(&query, result).await;
}

fn peb_reply(state: &LocalizationShared, request: &PebQuery) -> Result<PebReply, ErrorReply> {
    let anchors: Vec<[f64; 2]> = request
        .anchors
        .as_ref()
        .unwrap_or(&state.anchors)
        .iter()
        .map(|a| a.at)
        .collect();
    let model = model_of(&anchors, &state.sensing).map_err(|e| error_reply(&e))?;
    check_peb_work(request, anchors.len())?;
    match &request.at {
        PebWhere::Points(points) => {
            let bounds = bounds_at(&model, points, &state.fim).map_err(|e| error_reply(&e))?;
            let mut out = Vec::with_capacity(points.len());
            for (p, b) in points.iter().zip(bounds) {
                let finite = b.peb.is_finite();
                let gradient = if request.gradient {
                    peb_gradient(&model, *p, DEFAULT_GRADIENT_STEP_M, &state.fim)
                        .map_err(|e| error_reply(&e))?
                } else {
                    None
                };
                out.push(PebAt {
                    at: *p,
                    peb_m: finite.then_some(b.peb),
                    crb: finite.then(|| {
                        [
                            [b.crb[(0, 0)], b.crb[(0, 1)]],
                            [b.crb[(1, 0)], b.crb[(1, 1)]],
                        ]
                    }),
                    gradient,
                });
            }
            Ok(PebReply::Points(out))
        }
        PebWhere::Region(meta) if request.crb => {
            let field =
                crb_field(&model, &region_of(meta), &state.fim).map_err(|e| error_reply(&e))?;
            Ok(PebReply::Field {
                meta: *meta,
                cells: Cells::F32(field.peb),
                crb: Some(CrbCells {
                    xx: Cells::F32(field.crb_xx),
                    xy: Cells::F32(field.crb_xy),
                    yy: Cells::F32(field.crb_yy),
                }),
            })
        }
        PebWhere::Region(meta) => {
            let field =
                peb_field(&model, &region_of(meta), &state.fim).map_err(|e| error_reply(&e))?;
            Ok(PebReply::Field {
                meta: *meta,
                cells: Cells::F32(field.peb),
                crb: None,
            })
        }
    }
}

/// The most point-anchor evaluations one PEB query may cost (a 1000 × 1000 field with
/// 100 anchors, about a third of a CPU-second here): the cells and the anchors are each
/// bounded, but not their product, and 4 M cells × 4,096 anchors cost 45 CPU-seconds.
pub const MAX_PEB_WORK: u64 = 100_000_000;

/// Evaluations of one point's FIM per query point: a gradient takes four more
/// (central differences in x and y).
const GRADIENT_EVALUATIONS: u64 = 5;

/// Refuses a query whose cells (or points) × anchors is over [`MAX_PEB_WORK`], before any
/// of it is computed.
fn check_peb_work(request: &PebQuery, anchors: usize) -> Result<(), ErrorReply> {
    let (points, per_point) = match &request.at {
        PebWhere::Points(points) if request.gradient => (points.len() as u64, GRADIENT_EVALUATIONS),
        PebWhere::Points(points) => (points.len() as u64, 1),
        PebWhere::Region(meta) => (meta.cell_count(), 1),
    };
    let work = points
        .saturating_mul(per_point)
        .saturating_mul(anchors as u64);
    if work > MAX_PEB_WORK {
        return Err(ErrorReply::limit(
            "max_peb_work",
            MAX_PEB_WORK,
            work,
            format!(
                "{points} points × {anchors} anchors{} is {work} evaluations, over max_peb_work = {MAX_PEB_WORK}; query fewer or coarser cells, or fewer anchors",
                if per_point > 1 { " × 5 for the gradient" } else { "" }
            ),
        ));
    }
    Ok(())
}

fn region_of(meta: &GridMeta) -> GridRegion {
    GridRegion {
        origin: [meta.origin.x, meta.origin.y],
        resolution_m: meta.resolution,
        width: meta.width as usize,
        height: meta.height as usize,
    }
}

/// Sends the PEB field over the scenario's map to the map server as layer `peb`,
/// retrying until a map server answers (or the service stops).
async fn publish_peb_layer(state: Arc<LocalizationShared>, cancel: CancellationToken) {
    let anchors: Vec<[f64; 2]> = state.anchors.iter().map(|a| a.at).collect();
    let field = match model_of(&anchors, &state.sensing)
        .and_then(|m| peb_field(&m, &region_of(&state.map), &state.fim))
    {
        Ok(f) => f,
        Err(e) => return tracing::warn!("no PEB layer: {e}"),
    };
    let meta = GridMeta {
        origin: Origin {
            yaw: 0.0,
            ..state.map.origin
        },
        ..state.map
    };
    let requester = Requester::new(state.session.clone(), Duration::from_secs(5));
    loop {
        let sent = async {
            let list: LayerList = requester
                .request::<LayerList, LayerList>(&keys::map_index(&state.root), None)
                .await?;
            let base_version = list
                .layers
                .iter()
                .find(|l| l.name == PEB_LAYER)
                .map_or(0, |l| l.version);
            let update = LayerUpdate {
                base_version,
                change: LayerChange::Replace {
                    meta,
                    cells: Cells::F32(field.peb.clone()),
                },
                world: Some(state.world.clone()),
            };
            requester
                .request::<LayerUpdate, UpdateAck>(
                    &keys::map_update(&state.root, PEB_LAYER),
                    Some(&update),
                )
                .await
        };
        match sent.await {
            Ok(ack) => {
                return tracing::info!(version = ack.version, "PEB layer sent to the map server")
            }
            Err(e) => tracing::debug!("PEB layer not sent yet: {e}"),
        }
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(Duration::from_secs(1)) => {}
        }
    }
}
