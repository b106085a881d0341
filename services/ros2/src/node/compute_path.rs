//! Nav2's planner interface: the `nav2_msgs/action/ComputePathToPose` action server,
//! answered by roam's planner through Zenoh.
//!
//! A ROS 2 action is three services and two topics under `<action>/_action/`
//! (design.ros2.org's actions article; rmw_zenoh sees them as plain services and
//! topics): `send_goal` (the goal and its UUID → accepted), `get_result` (answered once
//! the goal is done), `cancel_goal` (`action_msgs/srv/CancelGoal`), and the `status`
//! (`action_msgs/msg/GoalStatusArray`, latched) and `feedback` topics. ComputePathToPose
//! has no feedback; its publisher is declared all the same, because a ROS 2 client
//! counts it before it calls the server available.
//!
//! What a goal gets, as Nav2's planner server does it: every well-formed goal is
//! accepted, then succeeds with the path or is aborted with one of Nav2's error codes
//! and a message.
//!
//! - `planner_id` picks the plan ([`PLANNER_IDS`]): empty or `curious` is the curious
//!   default (Model I), `GridBased` (the name in Nav2's default behaviour trees) and
//!   `shortest` the fastest path, and `model0`, `model1`, `model2`, `greedy`, `anytime`
//!   that planner; each curious plan has GetPlan's budget, 1.5 × the fastest path's ETA.
//!   Any other name: `INVALID_PLANNER`.
//! - `use_start` false starts at the robot's latest estimate ([`super::poses`]); with
//!   none, `TF_ERROR`, as Nav2 when it cannot look the robot up.
//! - A pose in a frame other than `map`: `TF_ERROR`. A start or goal off the map (or
//!   not finite): `START_OUTSIDE_MAP` / `GOAL_OUTSIDE_MAP`; in an obstacle or its
//!   inflation: `START_OCCUPIED` / `GOAL_OCCUPIED`; no path: `NO_VALID_PATH` (from the
//!   planner's refusal [`roam_proto::Cause`]); no plan within [`GOAL_ANSWER_S`]:
//!   `TIMEOUT`; the planner unreachable or busy: `UNKNOWN` with its reason.
//! - A cancel stops the goal's plan: the planner's own cancel is sent (the plan's future
//!   is dropped, and [`PlannerClient`] cancels what nobody waits for), and the goal ends
//!   `CANCELED` with an empty path.
//!
//! Bounded: at most [`MAX_RUNNING_GOALS`] goals are planned at once (the next is not
//! accepted), at most [`MAX_GOALS`] are remembered, a finished goal's result is kept
//! [`RESULT_KEPT`] (rcl_action's default result timeout), and a `get_result` waits at
//! most [`GOAL_ANSWER_S`] and a margin.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_proto::planner::PlannerModel;
use roam_proto::{Cause, ErrorReply};
use roam_runtime::Service;
use tokio::sync::watch;
use tokio_util::sync::CancellationToken;
use zenoh::query::Query;

use super::error::Ros2Error;
use super::output::Output;
use super::poses::RobotPoses;
use super::services::{self, answer_call, now};
use crate::action::GoalTable;
use crate::convert;
use crate::msg::{
    CancelGoalRequest, CancelGoalResponse, ComputePathGoal, ComputePathResult, GetResultRequest,
    GetResultResponse, GoalState, Nav2Error, SendGoalRequest, SendGoalResponse, Time, Uuid,
    CANCEL_REJECTED,
};
use crate::names::{EntityKind, Qos};
use crate::types;

/// Nav2's own name for the action (its planner server's), in the node's namespace.
pub const DEFAULT_ACTION: &str = "compute_path_to_pose";
/// Goals planned at once; a goal beyond them is not accepted.
pub const MAX_RUNNING_GOALS: usize = services::MAX_CONCURRENT_CALLS;
/// Goals remembered (running and finished); the oldest finished goes first.
pub const MAX_GOALS: usize = 256;
/// How long a finished goal's result can be fetched (rcl_action's default).
pub const RESULT_KEPT: Duration = Duration::from_secs(900);
/// The seconds a goal has for its plans (GetPlan's: a probe and a plan).
pub const GOAL_ANSWER_S: f64 = services::GET_PLAN_ANSWER_S;

/// The planner ids a goal may name, and the planner each asks for.
pub const PLANNER_IDS: &[(&str, PlannerModel)] = &[
    ("", PlannerModel::Model1),
    ("curious", PlannerModel::Model1),
    ("GridBased", PlannerModel::Shortest),
    ("shortest", PlannerModel::Shortest),
    ("model0", PlannerModel::Model0),
    ("model1", PlannerModel::Model1),
    ("model2", PlannerModel::Model2),
    ("greedy", PlannerModel::Greedy),
    ("anytime", PlannerModel::Anytime),
];

#[derive(Debug)]
struct Server {
    out: Arc<Output>,
    planner: PlannerClient,
    poses: Arc<RobotPoses>,
    /// The robot whose estimate starts a goal without `use_start`.
    robot: Option<String>,
    status_topic: String,
    goals: Mutex<GoalTable>,
    /// What stops each running goal's plan.
    running: Mutex<BTreeMap<Uuid, CancellationToken>>,
    /// Bumped at every goal's end: `get_result` waits on it.
    finished: watch::Sender<u64>,
}

/// Declares the action `action` (relative to the node's namespace): its three services
/// and two publishers, each with its liveliness token.
pub(crate) async fn declare(
    service: &Service,
    out: Arc<Output>,
    root: &str,
    action: &str,
    robot: Option<String>,
    poses: Arc<RobotPoses>,
) -> Result<(), Ros2Error> {
    let server = Arc::new(Server {
        planner: PlannerClient::new(out.session().clone(), root),
        out: out.clone(),
        poses,
        robot,
        status_topic: format!("{action}/_action/status"),
        goals: Mutex::new(GoalTable::new(MAX_RUNNING_GOALS, MAX_GOALS, RESULT_KEPT)),
        running: Mutex::new(BTreeMap::new()),
        finished: watch::channel(0).0,
    });
    out.declare(
        &format!("{action}/_action/feedback"),
        types::COMPUTE_PATH_FEEDBACK_MESSAGE,
        Qos::STREAM,
    )
    .await?;
    // rcl_action's status QoS: reliable, transient local, depth 1.
    server.publish_status().await;
    let mut tokens = Vec::new();
    for (part, ros_type) in [
        ("send_goal", types::COMPUTE_PATH_SEND_GOAL),
        ("get_result", types::COMPUTE_PATH_GET_RESULT),
        ("cancel_goal", types::CANCEL_GOAL),
    ] {
        let name = format!("{action}/_action/{part}");
        let endpoint = out.declared_endpoint(
            "action service",
            EntityKind::Service,
            &name,
            ros_type,
            Qos::SERVICE,
        )?;
        let queryable = service.declare_queryable(&endpoint.key).await?;
        tokens.push(out.token(&endpoint.token).await?);
        let key = endpoint.key.clone();
        let waiting = services::MAX_WAITING_CALLS;
        match part {
            "send_goal" => service.serve_up_to(queryable, waiting, server.clone(), move |s, q| {
                let key = key.clone();
                async move { send_goal(s, q, key).await }
            }),
            "get_result" => service.serve_up_to(queryable, waiting, server.clone(), move |s, q| {
                let key = key.clone();
                async move { get_result(s, q, key).await }
            }),
            _ => service.serve_up_to(queryable, waiting, server.clone(), move |s, q| {
                let key = key.clone();
                async move { cancel_goal(s, q, key).await }
            }),
        }
    }
    let cancel = service.cancel_token();
    service.spawn(async move {
        cancel.cancelled().await;
        drop(tokens);
    });
    Ok(())
}

impl Server {
    /// Every remembered goal's state on the latched status topic.
    async fn publish_status(&self) {
        let status = roam_runtime::lock(&self.goals).status();
        self.out
            .publish(
                &self.status_topic,
                types::GOAL_STATUS_ARRAY,
                Qos::LATCHED,
                &status,
            )
            .await;
    }

    /// Takes goal `id` in (see [`GoalTable::admit`]), with what cancels it.
    fn admit(&self, id: Uuid, cancel: CancellationToken) -> Result<Time, String> {
        // The token first: a cancel that comes as soon as the goal is admitted finds it.
        let stamp = now();
        let mut running = roam_runtime::lock(&self.running);
        roam_runtime::lock(&self.goals).admit(id, stamp, Instant::now())?;
        running.insert(id, cancel);
        Ok(stamp)
    }

    /// Ends goal `id` with `state` and `result` (unless it ended already).
    async fn finish(&self, id: Uuid, state: GoalState, result: ComputePathResult) {
        roam_runtime::lock(&self.running).remove(&id);
        let ended = roam_runtime::lock(&self.goals).finish(&id, state, result, Instant::now());
        if ended {
            self.finished.send_modify(|n| *n = n.wrapping_add(1));
            self.publish_status().await;
        }
    }

    /// Goal `id`'s state and result, once it is final or after `within`.
    async fn result_of(&self, id: &Uuid, within: Duration) -> (GoalState, ComputePathResult) {
        let mut finished = self.finished.subscribe();
        let deadline = tokio::time::Instant::now() + within;
        loop {
            {
                let goals = roam_runtime::lock(&self.goals);
                match goals.get(id) {
                    None => return (GoalState::Unknown, ComputePathResult::default()),
                    Some(goal) if goal.state.is_terminal() => {
                        return (goal.state, goal.result.clone())
                    }
                    Some(goal) if tokio::time::Instant::now() >= deadline => {
                        return (goal.state, ComputePathResult::default())
                    }
                    Some(_) => {}
                }
            }
            let _ = tokio::time::timeout_at(deadline, finished.changed()).await;
        }
    }

    /// The start and goal of `goal`, checked as Nav2 checks them.
    fn ends(&self, goal: &ComputePathGoal) -> Result<([f64; 2], [f64; 2]), Failure> {
        let goal_at = convert::pose_position("goal", &goal.goal).map_err(|e| match e {
            convert::PoseError::Frame(why) => Failure::new(Nav2Error::TfError, why),
            convert::PoseError::NotFinite(why) => Failure::new(Nav2Error::GoalOutsideMap, why),
        })?;
        let start_at = if goal.use_start {
            convert::pose_position("start", &goal.start).map_err(|e| match e {
                convert::PoseError::Frame(why) => Failure::new(Nav2Error::TfError, why),
                convert::PoseError::NotFinite(why) => Failure::new(Nav2Error::StartOutsideMap, why),
            })?
        } else {
            self.poses
                .current(self.robot.as_deref())
                .map_err(|why| Failure::new(Nav2Error::TfError, why))?
        };
        Ok((start_at, goal_at))
    }

    /// Goal's path, or Nav2's error code and why.
    async fn plan(&self, goal: &ComputePathGoal) -> Result<Vec<[f64; 2]>, Failure> {
        let model = PLANNER_IDS
            .iter()
            .find(|(id, _)| *id == goal.planner_id)
            .map(|(_, model)| *model)
            .ok_or_else(|| {
                let known: Vec<&str> = PLANNER_IDS
                    .iter()
                    .map(|(id, _)| *id)
                    .filter(|id| !id.is_empty())
                    .collect();
                Failure::new(
                    Nav2Error::InvalidPlanner,
                    format!(
                        "planner_id '{}' is not one of {} (empty: curious)",
                        roam_proto::excerpt::excerpt_n(&goal.planner_id, 64),
                        known.join(", ")
                    ),
                )
            })?;
        let (start, goal_at) = self.ends(goal)?;
        let within = Duration::from_secs_f64(GOAL_ANSWER_S);
        let plan = tokio::time::timeout(
            within,
            services::plan_by_budget_rule(&self.planner, start, goal_at, model),
        )
        .await
        .map_err(|_| {
            Failure::new(
                Nav2Error::Timeout,
                format!("roam's planner gave no plan within {GOAL_ANSWER_S} s"),
            )
        })?
        .map_err(|refusal| Failure::from_refusal(&refusal))?;
        Ok(plan.points)
    }

    /// Plans goal `id` to its end: succeeded, aborted, or canceled.
    async fn execute(self: Arc<Self>, id: Uuid, goal: ComputePathGoal, cancel: CancellationToken) {
        let started = Instant::now();
        let outcome = tokio::select! {
            outcome = self.plan(&goal) => Some(outcome),
            _ = cancel.cancelled() => None,
        };
        let planning_time = crate::msg::Duration::from_secs_f64(started.elapsed().as_secs_f64());
        let stamp = now();
        let (state, result) = match outcome {
            None => (
                GoalState::Canceled,
                ComputePathResult {
                    path: convert::path(&[], stamp),
                    planning_time,
                    error_code: 0,
                    error_msg: String::new(),
                },
            ),
            Some(Ok(points)) => (
                GoalState::Succeeded,
                ComputePathResult {
                    path: convert::path(&points, stamp),
                    planning_time,
                    error_code: 0,
                    error_msg: String::new(),
                },
            ),
            Some(Err(failure)) => {
                self.out.refuse(
                    &self.status_topic,
                    &format!(
                        "ComputePathToPose aborted ({}): {}",
                        failure.code as u16, failure.message
                    ),
                );
                (
                    GoalState::Aborted,
                    ComputePathResult {
                        path: convert::path(&[], stamp),
                        planning_time,
                        error_code: failure.code as u16,
                        error_msg: failure.message,
                    },
                )
            }
        };
        self.finish(id, state, result).await;
    }

    /// Sets the goals `request` names canceling (see [`GoalTable::cancel`]) and stops
    /// their plans.
    fn cancel(&self, request: &CancelGoalRequest) -> CancelGoalResponse {
        let response = roam_runtime::lock(&self.goals).cancel(request);
        let running = roam_runtime::lock(&self.running);
        for info in &response.goals_canceling {
            if let Some(token) = running.get(&info.goal_id) {
                token.cancel();
            }
        }
        response
    }
}

/// Why a goal was aborted: Nav2's code and a sentence.
#[derive(Debug)]
struct Failure {
    code: Nav2Error,
    message: String,
}

impl Failure {
    fn new(code: Nav2Error, message: impl Into<String>) -> Failure {
        Failure {
            code,
            message: message.into(),
        }
    }

    /// The planner's refusal as Nav2's code: by its cause where it has one.
    fn from_refusal(refusal: &ErrorReply) -> Failure {
        let code = match refusal.cause {
            Some(Cause::StartOffMap) => Nav2Error::StartOutsideMap,
            Some(Cause::GoalOffMap) => Nav2Error::GoalOutsideMap,
            Some(Cause::StartBlocked) => Nav2Error::StartOccupied,
            Some(Cause::GoalBlocked) => Nav2Error::GoalOccupied,
            Some(Cause::NoPath) => Nav2Error::NoValidPath,
            None => Nav2Error::Unknown,
        };
        Failure::new(code, refusal.to_string())
    }
}

async fn send_goal(server: Arc<Server>, query: Query, key: String) {
    let out = &server.out;
    let answer = |request: Result<SendGoalRequest<ComputePathGoal>, _>| async {
        let cancel = CancellationToken::new();
        let admitted = request
            .map_err(|e: crate::cdr::CdrError| e.to_string())
            .and_then(|request| {
                server
                    .admit(request.goal_id, cancel.clone())
                    .map(|stamp| (request, stamp))
            });
        match admitted {
            Ok((request, stamp)) => {
                let execute = server
                    .clone()
                    .execute(request.goal_id, request.goal, cancel);
                tokio::spawn(execute);
                server.publish_status().await;
                SendGoalResponse {
                    accepted: true,
                    stamp,
                }
            }
            Err(why) => {
                out.refuse(&key, &format!("goal not accepted: {why}"));
                SendGoalResponse {
                    accepted: false,
                    stamp: now(),
                }
            }
        }
    };
    answer_call(out, query, &key, "ComputePathToPose goal", answer).await;
}

async fn get_result(server: Arc<Server>, query: Query, key: String) {
    let server = &server;
    let answer = |request: Result<GetResultRequest, _>| async move {
        match request {
            Err(_) => GetResultResponse::<ComputePathResult>::default(),
            Ok(request) => {
                let within = Duration::from_secs_f64(GOAL_ANSWER_S) + Duration::from_secs(5);
                let (state, result) = server.result_of(&request.goal_id, within).await;
                GetResultResponse {
                    status: state as i8,
                    result,
                }
            }
        }
    };
    answer_call(
        &server.out,
        query,
        &key,
        "ComputePathToPose result request",
        answer,
    )
    .await;
}

async fn cancel_goal(server: Arc<Server>, query: Query, key: String) {
    let server = &server;
    let answer = |request: Result<CancelGoalRequest, _>| async move {
        let response = match request {
            Err(_) => CancelGoalResponse {
                return_code: CANCEL_REJECTED,
                goals_canceling: Vec::new(),
            },
            Ok(request) => server.cancel(&request),
        };
        if !response.goals_canceling.is_empty() {
            server.publish_status().await;
        }
        response
    };
    answer_call(&server.out, query, &key, "CancelGoal request", answer).await;
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::ErrorCode;

    #[test]
    fn the_planners_refusals_are_nav2s_codes() {
        for (cause, code) in [
            (Cause::StartOffMap, Nav2Error::StartOutsideMap),
            (Cause::GoalOffMap, Nav2Error::GoalOutsideMap),
            (Cause::StartBlocked, Nav2Error::StartOccupied),
            (Cause::GoalBlocked, Nav2Error::GoalOccupied),
            (Cause::NoPath, Nav2Error::NoValidPath),
        ] {
            let refusal = ErrorReply::new(ErrorCode::InvalidRequest, "why").with_cause(cause);
            assert_eq!(Failure::from_refusal(&refusal).code, code);
        }
        let busy = ErrorReply::new(ErrorCode::Busy, "queue full");
        let failure = Failure::from_refusal(&busy);
        assert_eq!(failure.code, Nav2Error::Unknown);
        assert!(failure.message.contains("queue full"));
    }

    #[test]
    fn every_planner_id_is_named_once() {
        let mut ids: Vec<&str> = PLANNER_IDS.iter().map(|(id, _)| *id).collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), PLANNER_IDS.len());
    }
}
