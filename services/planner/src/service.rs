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

use roam_runtime::Delivery;
use std::collections::BTreeSet;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use roam_proto::excerpt;
use roam_proto::layer_delta::{LayerDelta, MAX_DELTA_BYTES};
use roam_proto::map::Layer;
use roam_proto::planner::{CancelPlan, Plan, PlanProgress, PlanRequest, PlannerModel, StopReason};
use roam_proto::{keys, ErrorCode, ErrorReply};
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::{reply, Requester, Service, ServiceError};
use tokio_util::sync::CancellationToken;
use zenoh::query::Query;

use crate::budget::{CpuBudget, Exhausted};
use crate::config::PlannerConfig;
use crate::coupling::Coupling;
use crate::inflight::{CancelVerdict, InFlight};
use crate::limits::PlanLimits;
use crate::maps::{DeltaOutcome, MapCache};
use crate::params::GaParams;
use crate::plan::{check_spec, plan, PlanSpec};
use crate::queue::{ClientId, PlanQueue, QueueConfig, Refusal, Turn, MAX_QUEUED_PLANS};
use crate::scope::{self, PlanKeys};
use crate::token;
use crate::world::World;

/// Largest cancel decoded, bytes: an id and a token.
const MAX_CANCEL_BYTES: usize = 4 * 1024;

pub const SERVICE_NAME: &str = "planner";

/// Largest plan request accepted, in bytes.
pub const MAX_REQUEST_BYTES: usize = 64 * 1024;
/// The query parameter that names the client for its fair share of the queue
/// (`<root>/planner/plan?client=<name>`; [`crate::queue::ClientId`]).
pub const CLIENT_PARAMETER: &str = "client";

/// How often progress is published at most.
pub const PROGRESS_PERIOD: Duration = Duration::from_millis(50);

#[derive(Debug, thiserror::Error)]
pub enum PlannerError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error("invalid config: {0}")]
    Setting(#[from] SettingError),
}

/// A config setting outside its range: its name (as in the config file), the value
/// and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{name} = {value} is out of range; use {allowed}")]
pub struct SettingError {
    pub name: &'static str,
    pub value: String,
    pub allowed: String,
}

/// This planner instance, shared by its queryables and subscribers: its maps, its queue
/// and the plans it has in flight, its limits and its CPU budget.
struct PlannerInstance {
    root: String,
    instance: String,
    session: zenoh::Session,
    maps: Mutex<MapCache>,
    /// Plans running and queued (`max_concurrent_plans`, `max_queued_plans`).
    queue: PlanQueue,
    /// Plan requests received so far: each one's number is its place in the queue.
    arrivals: AtomicU64,
    plans: InFlight,
    limits: PlanLimits,
    budget: CpuBudget,
    /// Refused and unknown cancels, logged a few per window (`roam_runtime::warn_limit`).
    cancel_warnings: WarnLimiter,
    /// Layers to get whole (a delta did not apply to the version held), and the wake-up
    /// of the task that gets them: a burst of such deltas costs one `get` per layer.
    wanted: Mutex<BTreeSet<String>>,
    want: tokio::sync::Notify,
    /// Deltas ignored (a body naming another layer than its key), logged a few per
    /// window.
    delta_warnings: WarnLimiter,
}

impl PlannerInstance {
    fn maps(&self) -> MutexGuard<'_, MapCache> {
        roam_runtime::lock(&self.maps)
    }
}

/// Removes a request from the table of plans in flight however it ends.
struct Registration<'a> {
    plans: &'a InFlight,
    /// The plan's cancel key, which it is registered under.
    key: String,
}

impl Drop for Registration<'_> {
    fn drop(&mut self) {
        self.plans.remove(&self.key);
    }
}

/// Checks the config's numbers; names the first that is wrong.
pub fn check_config(config: &PlannerConfig) -> Result<(), PlannerError> {
    if config.max_concurrent_plans == 0 {
        return Err(PlannerError::Config(
            "max_concurrent_plans must be at least 1".into(),
        ));
    }
    if !(1..=MAX_QUEUED_PLANS).contains(&config.max_queued_plans) {
        return Err(SettingError {
            name: "max_queued_plans",
            value: config.max_queued_plans.to_string(),
            allowed: format!(
                "1..={MAX_QUEUED_PLANS} requests (each holds up to {} KiB while it waits)",
                MAX_REQUEST_BYTES / 1024
            ),
        }
        .into());
    }
    for (name, value) in [
        ("max_plan_cost", config.max_plan_cost),
        ("max_population_cells", config.max_population_cells),
    ] {
        if value == 0 {
            return Err(PlannerError::Config(format!("{name} must be at least 1")));
        }
    }
    config.budget().validate().map_err(PlannerError::Config)?;
    if let Some(value) = config.planning_resolution_m {
        use crate::resolution::MAX_PLANNING_RESOLUTION_M;
        if !(value.is_finite() && value > 0.0 && value <= MAX_PLANNING_RESOLUTION_M) {
            return Err(SettingError {
                name: crate::resolution::LIMIT_NAME,
                value: value.to_string(),
                allowed: format!("(0, {MAX_PLANNING_RESOLUTION_M}] metres, at least the map's resolution (paper 000: 0.2), or leave it out"),
            }
            .into());
        }
    }
    keys::check_name("information_layer", &config.information_layer)
        .map_err(|e| PlannerError::Config(e.to_string()))?;
    if config.coupling != Coupling::Max && config.change_layer.is_none() {
        return Err(PlannerError::Config(format!(
            "coupling: {} needs a change_layer to couple (the mapper's news layer): set change_layer: news, or leave coupling out",
            config.coupling.as_str()
        )));
    }
    if let Some(obstacles) = &config.obstacles_layer {
        keys::check_name("obstacles_layer", obstacles)
            .map_err(|e| PlannerError::Config(e.to_string()))?;
    }
    let inflation = config.obstacle_inflation_m;
    let most = crate::seen::MAX_OBSTACLE_INFLATION_M;
    if !(inflation.is_finite() && (0.0..=most).contains(&inflation)) {
        return Err(SettingError {
            name: "obstacle_inflation_m",
            value: inflation.to_string(),
            allowed: format!("0 to {most} metres"),
        }
        .into());
    }
    if let Some(change) = &config.change_layer {
        keys::check_name("change_layer", change)
            .map_err(|e| PlannerError::Config(e.to_string()))?;
        if *change == config.information_layer {
            return Err(PlannerError::Config(format!(
                "change_layer {change:?} is the information layer itself; name the mapper's change layer (change_information) or leave it out"
            )));
        }
    }
    Ok(())
}

/// Runs a planner instance until `cancel` is cancelled.
pub async fn run(
    config: PlannerConfig,
    zenoh_config: zenoh::Config,
    cancel: CancellationToken,
) -> Result<(), PlannerError> {
    check_config(&config)?;
    let mut service = Service::start(
        SERVICE_NAME,
        &config.root,
        config.instance.as_deref(),
        zenoh_config,
        cancel,
    )
    .await?;
    let state = Arc::new(PlannerInstance {
        root: config.root.clone(),
        instance: service.instance().to_owned(),
        session: service.session().clone(),
        maps: Mutex::new(
            MapCache::with_information(config.map_history, &config.information_layer)
                .coupling_change(config.change_layer.as_deref())
                .coupled_by(config.coupling)
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
    let root = config.root.as_str();

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

fn take_layer(state: &PlannerInstance, layer: Layer) {
    if let Some(version) = state.maps().update(layer) {
        tracing::info!(
            inflated = version.inflated,
            information = version.information,
            "planning on a new map"
        );
    }
}

/// A delta of a followed layer: applied, or (when it does not apply to the version
/// held) the whole layer is asked for.
fn take_delta(state: &PlannerInstance, delta: &LayerDelta) {
    match state.maps().apply_delta(delta) {
        DeltaOutcome::Applied(Some(version)) => tracing::info!(
            inflated = version.inflated,
            information = version.information,
            "planning on a new map"
        ),
        DeltaOutcome::Gap(why) => {
            tracing::debug!(layer = %excerpt(&delta.name), "getting the whole layer: {why}");
            roam_runtime::lock(&state.wanted).insert(delta.name.clone());
            state.want.notify_one();
        }
        DeltaOutcome::Applied(None) | DeltaOutcome::Held | DeltaOutcome::NotFollowed => {}
    }
}

/// Gets each layer a delta could not be applied to, whole.
async fn fetch_wanted(
    state: Arc<PlannerInstance>,
    requester: Requester,
    cancel: CancellationToken,
) {
    loop {
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = state.want.notified() => {}
        }
        let wanted = std::mem::take(&mut *roam_runtime::lock(&state.wanted));
        for name in wanted {
            match requester
                .request::<Layer, Layer>(&keys::map_layer(&state.root, &name), None)
                .await
            {
                Ok(layer) if layer.name == name => take_layer(&state, layer),
                Ok(_) => {
                    tracing::warn!(layer = %name, "the map server answered with another layer")
                }
                Err(e) => tracing::debug!("map layer {name} not fetched: {e}"),
            }
        }
    }
}

/// A cancel heard on `key`: honoured only for the plan registered under that key, with
/// the plan's own token ([`InFlight::cancel`]); refusals are logged, rate-limited, with
/// the id cut to an excerpt and never the token.
fn take_cancel(state: &PlannerInstance, key: &str, request: &CancelPlan) {
    let verdict = state.plans.cancel(key, request.token.as_deref());
    let id = || excerpt(&request.request_id).to_string();
    match verdict {
        CancelVerdict::Cancelled => {
            tracing::info!(request_id = %id(), "plan cancelled by its requester");
        }
        CancelVerdict::Unknown => {
            if let Some(suppressed) = state.cancel_warnings.allow("unknown") {
                tracing::debug!(request_id = %id(), suppressed, "cancel for a plan not in flight here; ignored");
            }
        }
        refused => {
            if let Some(suppressed) = state.cancel_warnings.allow("refused") {
                let why = match refused {
                    CancelVerdict::WrongToken => "its token is not the request's",
                    CancelVerdict::MissingToken => "it has no token",
                    _ => "the request had no cancel_token, so it cannot be cancelled",
                };
                tracing::warn!(
                    request_id = %id(),
                    suppressed,
                    "cancel ignored: {why} (only the requester, with its cancel_token, can cancel a plan)"
                );
            }
        }
    }
}

/// Gets the two layers from the map server, retrying until both arrive.
async fn fetch_maps(state: Arc<PlannerInstance>, requester: Requester, cancel: CancellationToken) {
    loop {
        let layers = state.maps().layers();
        for name in &layers {
            match requester
                .request::<Layer, Layer>(&keys::map_layer(&state.root, name), None)
                .await
            {
                Ok(layer) => take_layer(&state, layer),
                Err(e) => tracing::debug!("map layer {name} not available yet: {e}"),
            }
        }
        if state.maps().world(None).is_some() {
            return;
        }
        tokio::select! {
            _ = cancel.cancelled() => return,
            _ = tokio::time::sleep(Duration::from_millis(500)) => {}
        }
    }
}

async fn answer_plan(state: Arc<PlannerInstance>, query: Query, seq: u64, arrived: Instant) {
    let request = match reply::decode_request::<PlanRequest>(&query, MAX_REQUEST_BYTES) {
        Ok(r) => r,
        // The codec's refusals quote the payload only as a bounded excerpt.
        Err(e) => return reply::send_error(&query, &e).await,
    };
    let robot = match scope::robot_of_query(&state.root, query.key_expr().as_str()) {
        Ok(robot) => robot,
        Err(e) => {
            let refusal = ErrorReply::new(
                ErrorCode::InvalidRequest,
                format!("{e}: ask on one robot's plan key, or on the shared one"),
            );
            return reply::send_error(&query, &refusal).await;
        }
    };
    let client = query
        .parameters()
        .get(CLIENT_PARAMETER)
        .map_or_else(ClientId::anonymous, ClientId::named);
    let result = serve_plan(&state, request, robot, &client, seq, arrived).await;
    reply::send_result(&query, result).await;
}

/// A request checked and registered, ready for the queue.
struct Prepared<'a> {
    request: PlanRequest,
    request_id: String,
    plan_keys: PlanKeys,
    registration: Registration<'a>,
    stop: Arc<AtomicBool>,
    /// Cancelled with `stop`: wakes the request while it waits in the queue.
    wake: CancellationToken,
    map_version: roam_proto::planner::MapVersion,
    world: Arc<World>,
    spec: PlanSpec,
    /// Its work for the queue ([`crate::queue::units`]).
    units: f64,
    /// The generations `units` counts ([`crate::plan::Work::generations`]): the share of
    /// them a plan ran is the share of its units it did.
    sized_generations: u32,
}

/// Admits a request to the queue or refuses it at once, waits for its turn, plans.
async fn serve_plan(
    state: &Arc<PlannerInstance>,
    request: PlanRequest,
    robot: Option<&str>,
    client: &ClientId,
    seq: u64,
    arrived: Instant,
) -> Result<Plan, ErrorReply> {
    let prepared = prepare(state, request, robot)?;
    let max_plan_s = state.budget.config().max_plan_seconds;
    // The reply must reach the requester within its deadline: the plan ends earlier.
    let margin = reply_margin_s(prepared.spec.deadline_s);
    let mut ticket = state
        .queue
        .admit(
            seq,
            client,
            prepared.units,
            prepared.spec.deadline_s - margin,
            max_plan_s,
            arrived,
        )
        .map_err(|refusal| busy(state, refusal))?;
    if ticket.queued {
        // An empty progress message: the request is queued (its requester may cancel it).
        let message = PlanProgress {
            request_id: prepared.request_id.clone(),
            best_fitness: Vec::new(),
            done: false,
        };
        let key = &prepared.plan_keys.progress;
        roam_runtime::publish(&state.session, key, &message, Delivery::Latest).await;
    }
    let turn = ticket.wait_turn(&prepared.wake).await;
    if turn == Turn::Displaced {
        let (running, queued) = state.queue.load();
        return Err(ErrorReply::new(
            ErrorCode::Busy,
            format!(
                "planner {}'s queue is full ({queued} queued, {running} planning) and another client's request took this one's place: this client has the most requests queued; ask another instance or retry",
                state.instance
            ),
        ));
    }
    let Prepared {
        request,
        request_id,
        plan_keys,
        registration,
        stop,
        map_version,
        world,
        mut spec,
        sized_generations,
        ..
    } = prepared;
    // The deadline counts from the request's arrival: the wait was part of it.
    let left = ticket.remaining_s(spec.deadline_s - margin, Instant::now());
    let (cancelled_in_queue, out_of_time) = (turn == Turn::Cancelled, left < MIN_PLAN_S);
    let mut ticket = Some(ticket);
    if cancelled_in_queue || out_of_time {
        // Out of the queue at once; the reply is the floor (below), no GA: a usable
        // path now rather than a plan after the deadline.
        ticket = None;
        spec.model = PlannerModel::Shortest;
    } else {
        spec.deadline_s = left;
    }
    let outcome = tokio::task::spawn_blocking({
        let state = state.clone();
        move || {
            let result = plan_now(
                &state,
                &request,
                request_id,
                &plan_keys.progress,
                map_version,
                &world,
                spec,
                sized_generations,
                &stop,
            );
            (result, request)
        }
    })
    .await;
    drop(registration);
    let (result, request) = match outcome {
        Ok(done) => done,
        Err(e) => {
            return Err(ErrorReply::new(
                ErrorCode::Internal,
                format!("the planning task failed: {e}"),
            ))
        }
    };
    let (mut plan, share) = result?;
    if cancelled_in_queue || out_of_time {
        plan.model = request.model;
        plan.stop_reason = if cancelled_in_queue {
            StopReason::Cancelled
        } else {
            StopReason::Deadline
        };
        plan.generations = 0;
    }
    if let Some(ticket) = ticket {
        ticket.finish(share, Instant::now());
    }
    Ok(plan)
}

/// The least planning time worth starting a GA for, seconds: a request whose deadline
/// has (nearly) run out in the queue, because the wait was longer than expected, is
/// answered with the fastest path at once instead (`stop_reason: deadline`,
/// `generations: 0`).
const MIN_PLAN_S: f64 = 0.01;

/// What a plan leaves of its deadline for the reply to reach the requester (and for the
/// work after the GA: driving the path, the metrics): a tenth of the deadline, at most
/// 0.1 s.
pub fn reply_margin_s(deadline_s: f64) -> f64 {
    (0.1 * deadline_s).min(0.1)
}

/// Checks a request (for `robot`, or asked on the shared keys) against this instance's
/// state and registers it under its cancel key.
fn prepare<'a>(
    state: &'a PlannerInstance,
    request: PlanRequest,
    robot: Option<&str>,
) -> Result<Prepared<'a>, ErrorReply> {
    let request_id = request_id(&request)?;
    let plan_keys = PlanKeys::new(&state.root, robot, &request_id);
    if let Some(token) = &request.cancel_token {
        token::check_token(token)
            .map_err(|e| ErrorReply::new(ErrorCode::InvalidRequest, e.to_string()))?;
    }
    let (stop, wake) = state
        .plans
        .register(&plan_keys.cancel, request.cancel_token.clone())
        .map_err(|_| {
            ErrorReply::new(
                ErrorCode::InvalidRequest,
                format!(
                    "request id '{}' is already being planned on this instance; use a fresh id, or omit it",
                    excerpt(&request_id)
                ),
            )
        })?;
    let registration = Registration {
        plans: &state.plans,
        key: plan_keys.cancel.clone(),
    };
    let (map_version, world) = {
        let maps = state.maps();
        match maps.world(request.map_version) {
            Some(w) => w,
            None => {
                let have = maps.versions();
                return Err(match request.map_version {
                    Some(v) => ErrorReply::new(
                        ErrorCode::NotFound,
                        format!("map version {v:?} is unknown to this planner; it has {have:?}; omit map_version to plan on the latest"),
                    ),
                    None => match maps.last_error() {
                        Some(e) => ErrorReply::new(ErrorCode::Unavailable, format!("the planner cannot plan on the map it has: {e}")),
                        None => ErrorReply::new(ErrorCode::Unavailable, "the planner has no map yet; is the map server running under the same root?"),
                    },
                });
            }
        }
    };
    let params = GaParams::with_overrides(&request.params)
        .map_err(|e| ErrorReply::new(ErrorCode::InvalidRequest, e.to_string()))?;
    let spec = PlanSpec {
        start: request.start,
        goal: request.goal,
        t_exec_s: request.t_exec_s,
        deadline_s: request.deadline_s,
        model: request.model,
        params,
        seed: request.seed,
        threads: crate::ga::default_threads(),
        limits: state.limits,
        shortest: request.shortest,
    };
    // The numbers and the plan's size, before it is queued: what is refused for its
    // content is refused at once, not after a wait.
    check_spec(&spec).map_err(|e| e.to_reply())?;
    // A plan is sized by the generations that can start before its deadline: the GA
    // stops there, so what it could only do later is neither refused nor queued for.
    let work = crate::plan::work(&world, &spec).map_err(|e| e.to_reply())?;
    let units = crate::queue::units(work.cost);
    Ok(Prepared {
        request,
        request_id,
        plan_keys,
        registration,
        stop,
        wake,
        map_version,
        world,
        spec,
        units,
        sized_generations: work.generations,
    })
}

/// The refusal of a request the queue cannot serve within its deadline.
fn busy(state: &PlannerInstance, refusal: Refusal) -> ErrorReply {
    let (running, queued) = state.queue.load();
    let wait = refusal.expected_wait_s();
    let reply = match refusal {
        Refusal::Full { queued, .. } => {
            let max = state.queue.config().max_queued_plans;
            ErrorReply::limit(
                "max_queued_plans",
                max as u64,
                queued as u64 + 1,
                format!(
                    "planner {} has {queued} requests queued, its max_queued_plans, and {running} planning; the expected wait is {wait:.2} s: ask another instance or retry",
                    state.instance
                ),
            )
        }
        Refusal::Late {
            expected_plan_s,
            deadline_s,
            ..
        } => ErrorReply::new(
            ErrorCode::Busy,
            format!(
                "planner {} expects a wait of {wait:.2} s ({queued} queued, {running} planning) and about {expected_plan_s:.2} s of planning: past the deadline_s of {deadline_s} s; ask another instance, retry, or give a longer deadline_s",
                state.instance
            ),
        ),
    };
    reply.with_code(ErrorCode::Busy).with_expected_wait(wait)
}

/// The request's id, checked, or a fresh unguessable one ([`token::random_hex128`]).
fn request_id(request: &PlanRequest) -> Result<String, ErrorReply> {
    match &request.request_id {
        Some(id) => match keys::check_name("request id", id) {
            Ok(()) => Ok(id.clone()),
            Err(_) => Err(ErrorReply::new(
                ErrorCode::InvalidRequest,
                format!(
                    "request id '{}' cannot name a key: use 1 to {} characters from a-z, A-Z, 0-9, '_' and '-', or omit it and the planner makes one up",
                    excerpt(id),
                    keys::MAX_SEGMENT_LEN
                ),
            )),
        },
        None => Ok(token::random_hex128()),
    }
}

/// The refusal of a plan the CPU budget has no time for.
fn exhausted(state: &PlannerInstance, e: Exhausted) -> ErrorReply {
    let config = state.budget.config();
    let burst = config.plan_seconds_burst;
    ErrorReply::limit(
        "plan_seconds_burst",
        burst.ceil() as u64,
        (burst - e.available_s + e.needed_s).ceil().max(0.0) as u64,
        format!(
            "planner {} has spent its CPU budget: {:.1} of its {burst} plan-seconds are left (refilled at {} per second) and a plan needs {:.1}; retry in {:.1} s or ask another instance",
            state.instance,
            e.available_s.max(0.0),
            config.plan_seconds_per_second,
            e.needed_s,
            e.retry_in_s
        ),
    )
    .with_code(ErrorCode::Busy)
    .with_expected_wait(e.retry_in_s)
}

/// Plans a request whose turn has come (or the floor of one cancelled in the queue),
/// within the CPU budget, and builds the reply; with the share of its generations it
/// ran (of the `sized_generations` its queue units count), for the queue's rate.
#[allow(clippy::too_many_arguments)]
fn plan_now(
    state: &PlannerInstance,
    request: &PlanRequest,
    request_id: String,
    progress_key: &str,
    map_version: roam_proto::planner::MapVersion,
    world: &World,
    mut spec: PlanSpec,
    sized_generations: u32,
    stop: &AtomicBool,
) -> Result<(Plan, f64), ErrorReply> {
    let grant = state
        .budget
        .grant(spec.deadline_s, Instant::now())
        .map_err(|e| exhausted(state, e))?;
    spec.deadline_s = grant.seconds;

    let mut batch = Vec::new();
    let mut last_sent = Instant::now();
    let publish = |batch: &mut Vec<(u32, f64)>, done: bool| {
        let message = PlanProgress {
            request_id: request_id.clone(),
            best_fitness: std::mem::take(batch),
            done,
        };
        // The next batch of progress supersedes this one.
        roam_runtime::publish_wait(&state.session, progress_key, &message, Delivery::Latest);
    };
    let mut outcome = plan(world, &spec, stop, |generation, best| {
        batch.push((generation, best));
        if last_sent.elapsed() >= PROGRESS_PERIOD {
            publish(&mut batch, false);
            last_sent = Instant::now();
        }
    })
    .map_err(|e| e.to_reply())?;
    let (granted_s, cut) = (grant.seconds, grant.cut);
    grant.finish(Instant::now());
    publish(&mut batch, true);
    // The grant ended the plan only if it was shorter than the request's deadline.
    let cpu_grant_s = (cut && outcome.stop_reason == StopReason::Deadline).then(|| {
        outcome.stop_reason = StopReason::CpuGrant;
        granted_s
    });
    let share = if sized_generations == 0 || outcome.generations == 0 {
        1.0
    } else {
        f64::from(outcome.generations) / f64::from(sized_generations)
    };
    let mut plan = crate::answer::to_message(
        world,
        request,
        request_id.clone(),
        map_version,
        &state.instance,
        outcome,
    );
    plan.cpu_grant_s = cpu_grant_s;
    Ok((plan, share))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_news_coupling_needs_a_change_layer() {
        let alone = PlannerConfig {
            coupling: Coupling::News,
            ..PlannerConfig::default()
        };
        match check_config(&alone) {
            Err(PlannerError::Config(e)) => {
                assert!(
                    e.contains("coupling: news") && e.contains("change_layer"),
                    "{e}"
                )
            }
            other => panic!("{other:?}"),
        }
        let paired = PlannerConfig {
            change_layer: Some("news".into()),
            ..alone
        };
        assert!(check_config(&paired).is_ok());
    }
}
