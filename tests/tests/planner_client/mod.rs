//! What the planner's integration tests share: a request with the paper's settings cut
//! short, asking and being refused through Zenoh, a cancel put as a client puts it, and a
//! map server with planners booted on a harness. Included with `mod planner_client;`;
//! each test binary uses what it needs of it.
#![allow(dead_code)]

use roam_planner::PlannerConfig;
use roam_proto::planner::{
    CancelPlan, GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse,
};
use roam_proto::{encode, keys, ErrorReply};
use roam_runtime::{ClientError, Requester};
use roam_tests::{repo_path, within, Harness, RunningService};

/// A Model I request of `generations` generations of 60 (seed 11, 60 s deadline, no
/// shortest path attached).
pub fn request(start: [f64; 2], goal: [f64; 2], t_exec_s: f64, generations: u32) -> PlanRequest {
    PlanRequest {
        request_id: None,
        cancel_token: None,
        start,
        goal,
        t_exec_s,
        deadline_s: 60.0,
        model: PlannerModel::Model1,
        params: GaOverrides {
            max_generations: Some(generations),
            population: Some(60),
            ..GaOverrides::default()
        },
        seed: 11,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    }
}

/// Asks any planner instance for a plan.
pub async fn ask(
    client: &Requester,
    root: &str,
    request: &PlanRequest,
) -> Result<Plan, ClientError> {
    within(
        "plan",
        client.request(&keys::planner_plan(root), Some(request)),
    )
    .await
}

/// Asks for a plan that must be refused; the structured refusal.
pub async fn refusal(client: &Requester, root: &str, request: &PlanRequest) -> ErrorReply {
    match ask(client, root, request).await {
        Err(ClientError::Refused(reply)) => reply,
        other => panic!("expected a refusal, got {other:?}"),
    }
}

/// Puts a cancel for `id` with `token` from `session`.
pub async fn cancel(session: &zenoh::Session, root: &str, id: &str, token: Option<&str>) {
    within(
        "cancel",
        session.put(
            keys::planner_cancel(root, id),
            encode(&CancelPlan {
                request_id: id.into(),
                token: token.map(str::to_owned),
            }),
        ),
    )
    .await
    .expect("cancel put");
}

/// A harness with a map server and planners on it.
pub struct Running {
    pub harness: Harness,
    pub map_server: RunningService,
    pub planners: Vec<RunningService>,
}

/// A map server on `map` (a repository path; the built-in world when `None`) and one
/// planner per config `planners` makes for the harness.
pub async fn boot_on(
    map: Option<&str>,
    planners: impl FnOnce(&Harness) -> Vec<PlannerConfig>,
) -> Running {
    let harness = Harness::start().await;
    let map_server = harness
        .start_role(roam_map_server::MapServerConfig {
            map: map.map(repo_path),
            ..harness.map_server_config()
        })
        .await;
    let mut started = Vec::new();
    for config in planners(&harness) {
        started.push(harness.start_role(config).await);
    }
    Running {
        harness,
        map_server,
        planners: started,
    }
}

/// A map server on the built-in world and a planner per (instance name, plans at once).
pub async fn boot(planners: &[(&str, usize)]) -> Running {
    boot_with(planners, |config| config).await
}

/// [`boot`] with each planner's config changed by `adjust`.
pub async fn boot_with(
    planners: &[(&str, usize)],
    adjust: impl Fn(PlannerConfig) -> PlannerConfig,
) -> Running {
    boot_on(None, |harness| {
        planners
            .iter()
            .map(|(name, concurrent)| {
                adjust(PlannerConfig {
                    max_concurrent_plans: *concurrent,
                    ..harness.planner_config(name)
                })
            })
            .collect()
    })
    .await
}

impl Running {
    /// Stops every planner, then the map server; each must stop cleanly.
    pub async fn stop(self) {
        for planner in self.planners {
            planner.stop().await.1.expect("planner stops cleanly");
        }
        self.map_server
            .stop()
            .await
            .1
            .expect("map server stops cleanly");
        self.harness.close().await;
    }
}
