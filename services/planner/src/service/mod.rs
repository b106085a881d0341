//! The planner on Zenoh: a thin adapter around [`crate::plan::plan`].
//!
//! | key | kind | payload |
//! |---|---|---|
//! | `<root>/planner/plan` | queryable (every instance) | `plan_request` → `plan` |
//! | `<root>/planner/instance/<instance>/plan` | queryable (this instance) | `plan_request` → `plan` |
//! | `<root>/planner/progress/<request_id>` | publication | `plan_progress`, at most every 50 ms |
//! | `<root>/planner/cancel/*` | subscription | `cancel_plan`, honoured only with the request's `cancel_token` |
//! | `<root>/planner/robot/*/plan` | queryable (every instance) | `plan_request` → `plan`, a robot's plan ([`crate::scope`]) |
//! | `<root>/planner/instance/<instance>/robot/*/plan` | queryable (this instance) | the same on its own key |
//! | `<root>/planner/robot/<id>/progress/<request_id>` | publication | `plan_progress` of a robot's plan |
//! | `<root>/planner/robot/*/cancel/*` | subscription | `cancel_plan` of a robot's plan: only on that robot's key, with the token |
//! | `<root>/map/layer/{inflated,information,peb}` | subscription + get | `layer` |
//! | `<root>/map/delta/{inflated,information,peb}` | subscription | `layer_delta`, applied to the layer held at its base version; any other version gets the whole layer |
//!
//! Every plan is checked against this instance's limits before any work: its slot
//! (`max_concurrent_plans`), its size ([`crate::limits`]) and its wall time from the CPU
//! budget ([`crate::budget`]). Request ids and tokens are [`crate::token`]'s; who may
//! cancel is [`crate::inflight`]'s, on which keys [`crate::scope`]'s.

mod follow;
mod instance;
mod requests;
mod settings;

use std::collections::BTreeSet;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_proto::excerpt;
use roam_proto::keys;
use roam_proto::layer_delta::{LayerDelta, MAX_DELTA_BYTES};
use roam_proto::map::Layer;
use roam_proto::planner::CancelPlan;
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::{Requester, Service};
use tokio_util::sync::CancellationToken;

use crate::budget::CpuBudget;
use crate::config::PlannerConfig;
use crate::inflight::InFlight;
use crate::maps::MapCache;
use crate::queue::{PlanQueue, QueueConfig};

use follow::{fetch_maps, fetch_wanted, take_delta, take_layer};
use instance::{PlannerInstance, MAX_CANCEL_BYTES};
use requests::{answer_plan, take_cancel};

pub use instance::{CLIENT_PARAMETER, MAX_REQUEST_BYTES, PROGRESS_PERIOD};
pub use settings::{check_config, PlannerError, SettingError};

pub const SERVICE_NAME: &str = "planner";
/// Runs a planner instance until `cancel` is cancelled.
pub async fn run(
    config: PlannerConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), PlannerError> {
    check_config(&config)?;
    let mut service = Service::start(SERVICE_NAME, &config.service, zenoh_config, cancel).await?;
    let state = Arc::new(PlannerInstance {
        root: config.service.root.clone(),
        instance: service.instance().to_owned(),
        session: service.session().clone(),
        maps: Mutex::new(
            MapCache::with_information(config.map_history, &config.information_layer)
                .coupling_change(config.change_layer.as_deref())
                .coupled_by(config.coupling, config.news_floor)
                .avoiding_seen(
                    config.obstacles_layer.as_deref(),
                    config.obstacle_inflation_m,
                )
                .planning_at(config.planning_resolution_m),
        ),
        queue: PlanQueue::new(QueueConfig {
            max_concurrent_plans: config.max_concurrent_plans,
            max_queued_plans: config.max_queued_plans,
        }),
        arrivals: AtomicU64::new(0),
        plans: InFlight::default(),
        limits: config.limits(),
        budget: CpuBudget::new(config.budget(), Instant::now()),
        cancel_warnings: WarnLimiter::new(),
        wanted: Mutex::new(BTreeSet::new()),
        want: tokio::sync::Notify::new(),
        delta_warnings: WarnLimiter::new(),
    });
    let root = config.service.root.as_str();

    // Maps: follow publications, and fetch the current layers until we have them.
    let layers = state.maps().layers();
    for layer in &layers {
        service
            .subscribe(
                &keys::map_layer(root, layer),
                state.clone(),
                |state: &Arc<PlannerInstance>, layer: Layer| take_layer(state, layer),
            )
            .await?;
    }
    for layer in &layers {
        service
            .subscribe_with(
                &keys::map_delta(root, layer),
                MAX_DELTA_BYTES,
                state.clone(),
                |state: &Arc<PlannerInstance>, key: &str, delta: LayerDelta| {
                    // Keys decide: a delta is of the layer its key names.
                    if key.rsplit('/').next() == Some(delta.name.as_str()) {
                        take_delta(state, &delta)
                    } else {
                        roam_runtime::limited_warn!(
                            state.delta_warnings, "mismatch",
                            key = %excerpt(key), layer = %excerpt(&delta.name),
                            "delta ignored: its body names another layer than its key"
                        );
                    }
                },
            )
            .await?;
    }
    {
        let (state, cancel) = (state.clone(), service.cancel_token());
        let requester = Requester::new(service.session().clone(), Duration::from_secs(5));
        service.spawn(async move { fetch_maps(state, requester, cancel).await });
    }
    {
        let (state, cancel) = (state.clone(), service.cancel_token());
        let requester = Requester::new(service.session().clone(), Duration::from_secs(5));
        service.spawn(async move { fetch_wanted(state, requester, cancel).await });
    }
    for cancels in [
        keys::planner_cancel_any(root),
        keys::planner_robot_cancel_any(root),
    ] {
        service
            .subscribe_with(
                &cancels,
                MAX_CANCEL_BYTES,
                state.clone(),
                |state: &Arc<PlannerInstance>, key: &str, request: CancelPlan| {
                    // Keys decide: the request a cancel is for is the one its key names,
                    // and only the plan registered under that very key ([`crate::scope`]).
                    if key.rsplit('/').next() == Some(request.request_id.as_str()) {
                        take_cancel(state, key, &request)
                    } else if let Some(suppressed) = state.cancel_warnings.allow("mismatch") {
                        tracing::warn!(
                            key = %excerpt(key), request_id = %excerpt(&request.request_id), suppressed,
                            "cancel ignored: its body names another request than its key"
                        );
                    }
                },
            )
            .await?;
    }

    let instance = service.instance().to_owned();
    let mut queryables = Vec::new();
    for key in [
        keys::planner_plan(root),
        keys::planner_plan_at(root, &instance),
        keys::planner_robot_plan_any(root),
        keys::planner_robot_plan_at_any(root, &instance),
    ] {
        queryables.push(service.declare_queryable(&key).await?);
    }
    // Each request in the queue holds its query: room for all of them, and for the
    // refusals of a burst, which are answered at once.
    let max_in_flight = config.max_concurrent_plans + config.max_queued_plans + 64;
    for queryable in queryables {
        service.serve_up_to(queryable, max_in_flight, state.clone(), |s, q| {
            // Arrival order, taken as the query is received: the queue serves in it.
            let seq = s.arrivals.fetch_add(1, Ordering::Relaxed);
            let arrived = Instant::now();
            async move { answer_plan(s, q, seq, arrived).await }
        });
    }
    // The liveliness token means "ready to plan", so it waits for the first map.
    loop {
        if state.maps().world(None).is_some() {
            break;
        }
        tokio::select! {
            _ = service.cancelled() => break,
            _ = tokio::time::sleep(Duration::from_millis(20)) => {}
        }
    }
    if !service.cancel_token().is_cancelled() {
        service.announce().await?;
    }

    service.cancelled().await;
    // Stop every plan in flight: each returns its best path so far.
    state.plans.stop_all();
    service
        .shutdown(roam_runtime::service::DEFAULT_GRACE)
        .await?;
    Ok(())
}
