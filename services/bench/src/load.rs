//! `roam bench load`: many concurrent plan requests against two planner instances. Every
//! request must be answered, or refused `busy`, within its deadline; none may hang. It
//! measures what a fleet's burst of downtime plans does to a small planner pool.
//!
//! A stack (router, map server, two planners) runs in process; `requests` clients ask at
//! once through the round-robin [`PlannerClient`] (which skips busy instances and
//! reports `busy` only when every instance is busy). Each plan is Model I on the built-in
//! world with a deadline of `deadline_s` (default 1 s; the planners queue what can make
//! it, issue 16); a request counts as hung if no answer came within the deadline plus 5 s.

use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_proto::planner::{GaOverrides, PlanRequest, PlannerModel, ShortestPathUse};
use roam_proto::ErrorCode;
use roam_runtime::ClientError;
use serde::Serialize;
use tokio::task::JoinSet;

use crate::ms;
use crate::process::peak_rss_mib;
use crate::{setup, BenchError};
use roam_stack::stack::{Stack, StackOptions};

/// The most concurrent requests one run sends.
pub const MAX_REQUESTS: usize = 10_000;

#[derive(Debug, Clone, Serialize)]
pub struct LoadBench {
    pub requests: usize,
    pub planners: usize,
    /// Plans returned.
    pub answered: usize,
    /// Plans returned within their deadline, counted from the request.
    pub answered_within_deadline: usize,
    /// Refused with `busy` (every instance was at its concurrency limit).
    pub refused_busy: usize,
    /// Any other error (should be 0).
    pub failed: usize,
    /// No answer within the deadline plus 5 s (must be 0).
    pub hung: usize,
    /// Latency of the answered requests, request to decoded plan.
    pub answered_p50_ms: f64,
    pub answered_p99_ms: f64,
    /// Latency of the refusals: how fast a client learns it must retry.
    pub refused_p50_ms: f64,
    pub refused_max_ms: f64,
    pub max_ms: f64,
    /// The deadline each request carried.
    pub deadline_ms: f64,
    pub wall_s: f64,
    /// The process's peak resident memory (VmHWM), MiB.
    pub peak_rss_mib: Option<f64>,
}

enum Outcome {
    Answered(f64),
    Busy(f64),
    Failed(String),
    Hung,
}

/// The `q` quantile (nearest rank) of `samples`, which it sorts; 0 when empty.
pub(crate) fn percentile(samples: &mut [f64], q: f64) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    samples.sort_by(f64::total_cmp);
    let i = ((samples.len() - 1) as f64 * q).round() as usize;
    samples[i.min(samples.len() - 1)]
}

pub async fn load(requests: usize, deadline_s: f64) -> Result<LoadBench, BenchError> {
    let planners = 2;
    let stack = Stack::start(
        StackOptions {
            root: Some("roam-bench-load".into()),
            planners,
            ..StackOptions::default()
        },
        Duration::from_secs(30),
    )
    .await
    .map_err(setup)?;
    let deadline = Duration::from_secs_f64(deadline_s);
    let patience = deadline + Duration::from_secs(5);
    let client = PlannerClient::new(stack.router.session.clone(), &stack.root);
    // Both instances' tokens seen first, so the burst is spread over both.
    let seen = tokio::time::timeout(Duration::from_secs(30), async {
        while client.live_instances().await.map_or(0, |i| i.len()) < planners {
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    })
    .await;
    if seen.is_err() {
        return Err(BenchError::Setup(format!(
            "fewer than {planners} planner instances announced themselves"
        )));
    }
    let client = std::sync::Arc::new(client);
    let started = Instant::now();
    let mut tasks = JoinSet::new();
    for i in 0..requests {
        let client = client.clone();
        tasks.spawn(async move {
            let request = PlanRequest {
                request_id: Some(format!("load-{i}")),
                cancel_token: None,
                start: [-8.0, -8.0],
                goal: [-2.0, 4.0],
                t_exec_s: 60.0,
                deadline_s: deadline.as_secs_f64(),
                model: PlannerModel::Model1,
                params: GaOverrides {
                    max_generations: Some(300),
                    ..GaOverrides::default()
                },
                seed: i as u64,
                map_version: None,
                shortest: ShortestPathUse::Omit,
                seed_route: Vec::new(),
            };
            let asked = Instant::now();
            match tokio::time::timeout(patience, client.plan(&request)).await {
                Err(_) => Outcome::Hung,
                Ok(Ok(_)) => Outcome::Answered(ms(asked.elapsed())),
                Ok(Err(ClientError::Refused(reply))) if reply.code == ErrorCode::Busy => {
                    Outcome::Busy(ms(asked.elapsed()))
                }
                Ok(Err(e)) => Outcome::Failed(e.to_string()),
            }
        });
    }
    let (mut answered, mut busy, mut failed, mut hung) = (Vec::new(), Vec::new(), 0, 0);
    while let Some(joined) = tasks.join_next().await {
        match joined {
            Ok(Outcome::Answered(t)) => answered.push(t),
            Ok(Outcome::Busy(t)) => busy.push(t),
            Ok(Outcome::Failed(e)) => {
                tracing::warn!("a load request failed: {e}");
                failed += 1;
            }
            Ok(Outcome::Hung) => hung += 1,
            Err(e) => {
                tracing::warn!("a load request task failed: {e}");
                failed += 1;
            }
        }
    }
    let wall_s = started.elapsed().as_secs_f64();
    let max_ms = answered
        .iter()
        .chain(busy.iter())
        .copied()
        .fold(0.0, f64::max);
    let within = answered.iter().filter(|&&t| t <= ms(deadline)).count();
    let refused_max_ms = busy.iter().copied().fold(0.0, f64::max);
    let result = LoadBench {
        requests,
        planners,
        answered: answered.len(),
        answered_within_deadline: within,
        refused_max_ms,
        refused_busy: busy.len(),
        failed,
        hung,
        answered_p50_ms: percentile(&mut answered, 0.5),
        answered_p99_ms: percentile(&mut answered, 0.99),
        refused_p50_ms: percentile(&mut busy, 0.5),
        max_ms,
        deadline_ms: ms(deadline),
        wall_s,
        peak_rss_mib: peak_rss_mib(),
    };
    stack.shutdown().await.map_err(setup)?;
    Ok(result)
}
