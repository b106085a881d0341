//! A plan request from arrival to reply: decoded, checked against this instance's
//! limits, admitted to the queue or refused at once, planned when its turn comes within
//! the CPU budget, answered; and cancels, honoured only with the request's token.

use roam_runtime::Delivery;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

use roam_proto::excerpt;
use roam_proto::planner::{CancelPlan, Plan, PlanProgress, PlanRequest, PlannerModel, StopReason};
use roam_proto::{keys, ErrorCode, ErrorReply};
use roam_runtime::reply;
use tokio_util::sync::CancellationToken;
use zenoh::query::Query;

use crate::budget::Exhausted;
use crate::inflight::CancelVerdict;
use crate::params::GaParams;
use crate::plan::{check_spec, plan, PlanSpec};
use crate::queue::{ClientId, Refusal, Turn};
use crate::scope::{self, PlanKeys};
use crate::token;
use crate::world::World;

use super::instance::{
    PlannerInstance, Registration, CLIENT_PARAMETER, MAX_REQUEST_BYTES, PROGRESS_PERIOD,
};

/// A cancel heard on `key`: honoured only for the plan registered under that key, with
/// the plan's own token ([`InFlight::cancel`]); refusals are logged, rate-limited, with
/// the id cut to an excerpt and never the token.
pub(super) fn take_cancel(state: &PlannerInstance, key: &str, request: &CancelPlan) {
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

pub(super) async fn answer_plan(
    state: Arc<PlannerInstance>,
    query: Query,
    seq: u64,
    arrived: Instant,
) {
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
        seed_route: request.seed_route.clone(),
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
