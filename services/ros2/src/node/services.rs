//! The planner as two ROS 2 services, with rmw_zenoh's conventions: a queryable declared
//! `complete` on the service's key, the request's CDR as the query's payload and its
//! attachment (sequence number, timestamp, client GID) echoed in the reply's, with the
//! reply's own timestamp.
//!
//! - `/roam/plan_downtime` (`roam_interfaces/srv/PlanDowntime`): roam's plan request
//!   and plan; every refusal comes back in `error_code` and `error_message`.
//! - `/roam/get_plan` (`nav_msgs/srv/GetPlan`), for tools that know only that type. Its
//!   budget rule: the shortest path's ETA (Eq. 2, from the planner's `shortest` model)
//!   times [`GET_PLAN_BUDGET_FACTOR`], planned with Model I, seed 0, in at most
//!   [`crate::convert::DEFAULT_DEADLINE_S`] s. GetPlan has no error field: a refusal is
//!   an empty path (nav_msgs' own convention for "no plan") and a logged line with the
//!   reason; `tolerance` is ignored (roam plans to the goal cell).
//!
//! **Every call is answered.** A ROS 2 client waits for its response with no timeout of
//! its own, so the node never leaves a call unanswered: at most
//! [`MAX_CONCURRENT_CALLS`] calls of each service are planned at once, a call beyond
//! them is answered at once (an empty path for GetPlan, `busy` for PlanDowntime), and a
//! GetPlan call has [`GET_PLAN_ANSWER_S`] for its two plans before it is answered with
//! an empty path. Up to [`MAX_WAITING_CALLS`] calls are taken from Zenoh at once, so
//! that the ones beyond capacity get their answer instead of waiting in Zenoh's channel.
//!
//! Both call roam's planner through Zenoh ([`roam_planner::client::PlannerClient`]), as
//! any client would. A request that is not valid CDR gets `malformed` (PlanDowntime) or an
//! empty path (GetPlan), a NaN or a frame other than `map` `invalid_request`; a query
//! without rmw_zenoh's attachment cannot be answered as ROS 2 (no sequence number to
//! echo), so it gets a Zenoh error reply saying so.

use std::sync::Arc;

use roam_planner::client::PlannerClient;
use roam_proto::planner::{Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_proto::{Cause, ErrorCode, ErrorReply};
use roam_runtime::{ClientError, Service};
use serde::Serialize;
use zenoh::query::Query;

use super::error::Ros2Error;
use super::output::Output;
use crate::attachment::{self, Attachment};
use crate::convert;
use crate::msg::{GetPlanRequest, GetPlanResponse, PlanDowntimeRequest, Time};
use crate::names::{EntityKind, Qos};
use crate::types;

/// `/roam/get_plan`'s budget: this many times the shortest path's ETA.
pub const GET_PLAN_BUDGET_FACTOR: f64 = 1.5;
/// The budget of the shortest-path probe behind `/roam/get_plan`, seconds.
pub const GET_PLAN_PROBE_BUDGET_S: f64 = 3600.0;
/// The largest request read: two poses, a few numbers and a model name.
pub const MAX_REQUEST_BYTES: usize = 16 * 1024;
/// Calls of one service planned at once; the next are answered at once.
pub const MAX_CONCURRENT_CALLS: usize = 16;
/// Calls of one service taken from Zenoh at once (planned or being refused).
pub const MAX_WAITING_CALLS: usize = 1024;
/// The seconds a GetPlan call has for its shortest-path probe and its plan.
pub const GET_PLAN_ANSWER_S: f64 = 2.0 * crate::convert::DEFAULT_DEADLINE_S + 2.0;

pub const PLAN_DOWNTIME: &str = "roam/plan_downtime";
pub const GET_PLAN: &str = "roam/get_plan";

#[derive(Clone)]
struct State {
    out: Arc<Output>,
    planner: Arc<PlannerClient>,
    /// One permit per call being planned ([`MAX_CONCURRENT_CALLS`]).
    calls: Arc<tokio::sync::Semaphore>,
}

impl State {
    /// A permit to plan a call now, or the refusal that answers it at once.
    fn take_call(&self) -> Result<tokio::sync::OwnedSemaphorePermit, ErrorReply> {
        self.calls.clone().try_acquire_owned().map_err(|_| {
            ErrorReply::new(
                ErrorCode::Busy,
                format!("{MAX_CONCURRENT_CALLS} calls are being planned; retry in a moment"),
            )
        })
    }
}

pub(crate) async fn declare(
    service: &Service,
    out: Arc<Output>,
    root: &str,
) -> Result<(), Ros2Error> {
    let fresh_state = || State {
        planner: Arc::new(PlannerClient::new(out.session().clone(), root)),
        out: out.clone(),
        calls: Arc::new(tokio::sync::Semaphore::new(MAX_CONCURRENT_CALLS)),
    };
    let mut tokens = Vec::new();
    for (name, ros_type) in [
        (PLAN_DOWNTIME, types::PLAN_DOWNTIME),
        (GET_PLAN, types::GET_PLAN),
    ] {
        let endpoint =
            out.declared_endpoint("service", EntityKind::Service, name, ros_type, Qos::SERVICE)?;
        let queryable = service.declare_queryable(&endpoint.key).await?;
        tokens.push(out.token(&endpoint.token).await?);
        let key = endpoint.key.clone();
        if name == PLAN_DOWNTIME {
            service.serve_up_to(queryable, MAX_WAITING_CALLS, fresh_state(), move |s, q| {
                let key = key.clone();
                async move { plan_downtime(s, q, key).await }
            });
        } else {
            service.serve_up_to(queryable, MAX_WAITING_CALLS, fresh_state(), move |s, q| {
                let key = key.clone();
                async move { get_plan(s, q, key).await }
            });
        }
    }
    // The tokens live as long as the service.
    let cancel = service.cancel_token();
    service.spawn(async move {
        cancel.cancelled().await;
        drop(tokens);
    });
    Ok(())
}

/// The request's attachment, or a Zenoh error reply saying why it cannot be answered.
pub(crate) async fn request_attachment(
    out: &Output,
    query: &Query,
    key: &str,
) -> Option<Attachment> {
    let parsed = match query.attachment() {
        Some(bytes) => Attachment::parse(&bytes.to_bytes()).map_err(|e| e.to_string()),
        None => Err("no attachment".to_owned()),
    };
    match parsed {
        Ok(a) => Some(a),
        Err(why) => {
            let reason = format!("not an rmw_zenoh request ({why}): a ROS 2 service call carries the 33-byte attachment (sequence number, timestamp, client GID)");
            out.refuse(key, &reason);
            let _ = query.reply_err(reason).await;
            None
        }
    }
}

/// Answers one ROS 2 call the rmw_zenoh way: a query without the attachment gets a Zenoh
/// error reply; otherwise the request is decoded (up to [`MAX_REQUEST_BYTES`]; a request
/// that is not valid CDR is logged and given to `answer` as the error), `answer` makes
/// the response, and the reply echoes the request's sequence number and GID.
pub(crate) async fn answer_call<Req, Resp, Fut>(
    out: &Output,
    query: Query,
    key: &str,
    what: &'static str,
    answer: impl FnOnce(Result<Req, crate::cdr::CdrError>) -> Fut,
) where
    Req: serde::de::DeserializeOwned,
    Resp: Serialize,
    Fut: std::future::Future<Output = Resp>,
{
    let Some(att) = request_attachment(out, &query, key).await else {
        return;
    };
    let request = crate::cdr::decode::<Req>(&payload(&query), what, MAX_REQUEST_BYTES);
    if let Err(e) = &request {
        out.refuse(key, &e.to_string());
    }
    let response = answer(request).await;
    reply(out, &query, key, &att, &response).await;
}

/// Replies with `response` on the service's key, the request's sequence number and GID.
pub(crate) async fn reply<T: Serialize>(
    out: &Output,
    query: &Query,
    key: &str,
    request: &Attachment,
    response: &T,
) {
    let bytes = match crate::cdr::encode(response) {
        Ok(bytes) => bytes,
        Err(e) => return tracing::warn!(%key, "roam ros2: no reply: {e}"),
    };
    let attachment = Attachment {
        sequence_number: request.sequence_number,
        source_timestamp_ns: attachment::now_ns(),
        gid: request.gid,
    };
    if let Err(e) = query
        .reply(key.to_owned(), bytes)
        .attachment(attachment.to_bytes().to_vec())
        .await
    {
        out.refuse(key, &format!("reply failed: {e}"));
    }
}

pub(crate) fn payload(query: &Query) -> Vec<u8> {
    query
        .payload()
        .map(|p| p.to_bytes().to_vec())
        .unwrap_or_default()
}

pub(crate) fn now() -> Time {
    Time::from_nanos(attachment::now_ns())
}

pub(crate) fn client_error(e: ClientError) -> ErrorReply {
    match e {
        ClientError::Refused(reply) => reply,
        other => ErrorReply::new(
            ErrorCode::Unavailable,
            format!("roam's planner did not answer: {other}"),
        ),
    }
}

async fn plan_downtime(state: State, query: Query, key: String) {
    let out = &state.out;
    let Some(att) = request_attachment(out, &query, &key).await else {
        return;
    };
    let outcome = match crate::cdr::decode::<PlanDowntimeRequest>(
        &payload(&query),
        "PlanDowntime request",
        MAX_REQUEST_BYTES,
    ) {
        Err(e) => Err(ErrorReply::new(ErrorCode::Malformed, e.to_string())),
        Ok(request) => match (convert::plan_downtime_request(&request), state.take_call()) {
            (Err(refusal), _) | (Ok(_), Err(refusal)) => Err(refusal),
            (Ok(plan_request), Ok(_call)) => state
                .planner
                .plan(&plan_request)
                .await
                .map_err(client_error),
        },
    };
    let response = match outcome {
        Ok(plan) => convert::plan_downtime_response(&plan, now()),
        Err(refusal) => {
            out.refuse(&key, &refusal.to_string());
            convert::plan_downtime_refusal(&refusal, now())
        }
    };
    reply(out, &query, &key, &att, &response).await;
}

/// GetPlan's budget rule, shared with ComputePathToPose: the shortest path's ETA (a
/// probe with the planner's `shortest` model) times [`GET_PLAN_BUDGET_FACTOR`] is the
/// budget of a `model` plan; `shortest` is the probe itself.
pub(crate) async fn plan_by_budget_rule(
    planner: &PlannerClient,
    start: [f64; 2],
    goal: [f64; 2],
    model: PlannerModel,
) -> Result<Plan, ErrorReply> {
    let probe = PlanRequest {
        request_id: None,
        cancel_token: None,
        start,
        goal,
        t_exec_s: GET_PLAN_PROBE_BUDGET_S,
        deadline_s: convert::DEFAULT_DEADLINE_S,
        model: PlannerModel::Shortest,
        params: Default::default(),
        seed: 0,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let shortest = planner.plan(&probe).await.map_err(client_error)?;
    if !shortest.reaches_goal {
        return Err(
            ErrorReply::new(ErrorCode::NotFound, "no path reaches the goal")
                .with_cause(Cause::NoPath),
        );
    }
    if model == PlannerModel::Shortest {
        return Ok(shortest);
    }
    let curious = PlanRequest {
        t_exec_s: (shortest.t_eta_s * GET_PLAN_BUDGET_FACTOR).max(shortest.t_eta_s + 1.0),
        model,
        ..probe
    };
    planner.plan(&curious).await.map_err(client_error)
}

/// GetPlan's plan: a Model I plan by the budget rule.
async fn get_plan_path(
    state: &State,
    request: &GetPlanRequest,
) -> Result<Vec<[f64; 2]>, ErrorReply> {
    let (start, goal) = convert::get_plan_ends(request)?;
    let plan = plan_by_budget_rule(&state.planner, start, goal, PlannerModel::Model1).await?;
    Ok(plan.points)
}

async fn get_plan(state: State, query: Query, key: String) {
    let out = &state.out;
    let Some(att) = request_attachment(out, &query, &key).await else {
        return;
    };
    let points = match crate::cdr::decode::<GetPlanRequest>(
        &payload(&query),
        "GetPlan request",
        MAX_REQUEST_BYTES,
    ) {
        Err(e) => Err(ErrorReply::new(ErrorCode::Malformed, e.to_string())),
        Ok(request) => match state.take_call() {
            Err(busy) => Err(busy),
            Ok(_call) => {
                let within = std::time::Duration::from_secs_f64(GET_PLAN_ANSWER_S);
                tokio::time::timeout(within, get_plan_path(&state, &request))
                    .await
                    .unwrap_or_else(|_| {
                        Err(ErrorReply::new(
                            ErrorCode::Unavailable,
                            format!("roam's planner gave no plan within {GET_PLAN_ANSWER_S} s"),
                        ))
                    })
            }
        },
    };
    let points = points.unwrap_or_else(|refusal| {
        out.refuse(
            &key,
            &format!("GetPlan answered with an empty path: {refusal}"),
        );
        Vec::new()
    });
    let response = GetPlanResponse {
        plan: convert::path(&points, now()),
    };
    reply(out, &query, &key, &att, &response).await;
}
