//! The planner under maximal requests within its limits: each is answered within its
//! per-plan CPU budget (cut there, with its best path so far) or refused `busy` at once,
//! so a few clients cannot hold the cores for minutes.

use std::time::{Duration, Instant};

use roam_proto::planner::{
    GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse, StopReason,
};
use roam_proto::{keys, ErrorCode};
use roam_runtime::{ClientError, Requester};

/// The planner's `max_plan_seconds` in this test (its config file says so).
pub(crate) const MAX_PLAN_SECONDS: f64 = 3.0;
/// How far past the budget an answer may come (replying, a debug build's last
/// generation).
const MARGIN: Duration = Duration::from_secs(5);

/// The planner's config for this test.
pub(crate) fn config() -> String {
    format!("max_plan_seconds: {MAX_PLAN_SECONDS}\n")
}

/// Three maximal requests at once (population 2000, as many generations as
/// `max_plan_cost` admits, a 600 s deadline); returns the slowest answer.
pub(crate) async fn maximal_plans(session: &zenoh::Session, root: &str) -> Duration {
    let client = Requester::new(session.clone(), Duration::from_secs(120));
    let request = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [-8.0, -8.0],
        goal: [6.0, -7.0],
        t_exec_s: 80.0,
        deadline_s: 600.0,
        model: PlannerModel::Model1,
        params: GaOverrides {
            population: Some(2000),
            max_generations: Some(4000),
            ..GaOverrides::default()
        },
        seed: 0,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let key = keys::planner_plan(root);
    let asks: Vec<_> = (0..3)
        .map(|_| {
            let (client, key, request) = (client.clone(), key.clone(), request.clone());
            tokio::spawn(async move {
                let t = Instant::now();
                let r = client
                    .request::<PlanRequest, Plan>(&key, Some(&request))
                    .await;
                (r, t.elapsed())
            })
        })
        .collect();
    let mut slowest = Duration::ZERO;
    for ask in asks {
        let (result, took) = ask.await.expect("task");
        slowest = slowest.max(took);
        assert!(
            took <= Duration::from_secs_f64(MAX_PLAN_SECONDS) + MARGIN,
            "a maximal plan held the planner {took:?}"
        );
        match result {
            Ok(plan) => assert_eq!(
                plan.stop_reason,
                StopReason::CpuGrant,
                "{:?}",
                plan.stop_reason
            ),
            Err(ClientError::Refused(e)) => assert!(
                matches!(e.code, ErrorCode::Busy | ErrorCode::LimitExceeded),
                "{e}"
            ),
            Err(e) => panic!("no answer: {e}"),
        }
    }
    slowest
}
