//! `roam bench planner`: the GA's speed per curiosity model, and what the service adds.
//!
//! On the built-in 20 × 20 m world at 0.2 m (paper scale), from the start to Goal 2 with
//! twice the shortest path's ETA as budget, Table I's population (200) and generations
//! (2000), fixed seeds: each model plans `runs` times in process. Then a short plan (20
//! generations) runs in process and through a running stack (router, map server,
//! planner) alternately; the overhead is the median round trip minus the median
//! in-process time.

use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::{GaOverrides, PlanRequest, PlannerModel, ShortestPathUse};
use roam_runtime::SessionArgs;
use serde::Serialize;

use crate::ms;
use crate::{setup, BenchError};
use roam_experiments::progress::{Done, Progress};
pub use roam_experiments::reproduce::planner::builtin_world;
use roam_stack::stack::{Stack, StackOptions};

#[derive(Debug, Clone, Serialize)]
pub struct ModelBench {
    pub plan_s_median: f64,
    pub evals_per_s: f64,
    /// Genes evaluated per second: the GA's speed per unit of work, which (unlike
    /// `evals_per_s`) does not fall when the paths it works on are longer.
    pub genes_per_s: f64,
    /// Cells of the returned path.
    pub path_cells_median: f64,
    pub generations: u32,
    pub distinct_information_median: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct PlannerBench {
    pub models: BTreeMap<String, ModelBench>,
    pub model2_over_model1: f64,
    pub zenoh_overhead_ms_median: f64,
    pub runs: usize,
    /// `paper` (paper 000's initialization, `--paper-init`) or `roam` (the default).
    pub initialization: String,
}

pub const START: [f64; 2] = [-8.0, -8.0];
pub const GOAL: [f64; 2] = [6.0, -7.0];

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

fn spec(model: PlannerModel, t_exec_s: f64, seed: u64, generations: u32) -> PlanSpec {
    PlanSpec::batch(START, GOAL, t_exec_s, model, generations, seed)
}

/// Runs the benchmark; `paper_initialization` plans the in-process runs with paper
/// 000's initialization (no via-point seeds, walks that stop at the goal) to compare;
/// `progress` after each plan (stage `plans`) and each round trip (`round trips`).
pub async fn planner(
    runs: usize,
    paper_initialization: bool,
    progress: Progress<'_>,
) -> Result<PlannerBench, BenchError> {
    let world = builtin_world()?;
    let never = AtomicBool::new(false);
    let shortest = plan(
        &world,
        &spec(PlannerModel::Shortest, 86_400.0, 0, 1),
        &never,
        |_, _| {},
    )
    .map_err(setup)?;
    let budget = 2.0 * shortest.t_eta_s;
    let mut models = BTreeMap::new();
    let all = [
        PlannerModel::Model0,
        PlannerModel::Model1,
        PlannerModel::Model2,
    ];
    let mut planned = 0;
    for model in all {
        let mut seconds = Vec::new();
        let mut rates = Vec::new();
        let mut gene_rates = Vec::new();
        let mut cells = Vec::new();
        let mut info = Vec::new();
        let mut generations = 0;
        for run in 0..runs {
            let mut s = spec(model, budget, run as u64, 2000);
            if paper_initialization {
                s.params = s.params.with_paper_initialization();
            }
            let started = Instant::now();
            let outcome = plan(&world, &s, &never, |_, _| {}).map_err(setup)?;
            let elapsed = started.elapsed().as_secs_f64();
            seconds.push(elapsed);
            rates.push(outcome.evaluations as f64 / elapsed);
            gene_rates.push(outcome.evaluated_genes as f64 / elapsed);
            cells.push(outcome.path.len() as f64);
            info.push(outcome.metrics.distinct_information);
            generations = outcome.generations;
            planned += 1;
            progress(Done::of("plans", "plans", planned, all.len() * runs));
        }
        models.insert(
            model.as_str().to_owned(),
            ModelBench {
                plan_s_median: median(&mut seconds),
                evals_per_s: median(&mut rates),
                genes_per_s: median(&mut gene_rates),
                path_cells_median: median(&mut cells),
                generations,
                distinct_information_median: median(&mut info),
            },
        );
    }
    let ratio = models["model2"].plan_s_median / models["model1"].plan_s_median;
    let overhead = zenoh_overhead(&world, budget, runs.max(10), progress).await?;
    Ok(PlannerBench {
        models,
        model2_over_model1: ratio,
        zenoh_overhead_ms_median: overhead,
        runs,
        initialization: if paper_initialization {
            "paper"
        } else {
            "roam"
        }
        .to_owned(),
    })
}

/// Median service round trip minus median in-process time for the same short plan.
async fn zenoh_overhead(
    world: &World,
    budget: f64,
    runs: usize,
    progress: Progress<'_>,
) -> Result<f64, BenchError> {
    let stack = Stack::start(
        StackOptions {
            root: Some("roam-bench-planner".into()),
            planners: 1,
            ..StackOptions::default()
        },
        Duration::from_secs(30),
    )
    .await
    .map_err(setup)?;
    let result = async {
        let config = SessionArgs::client_of(&stack.router.endpoint)
            .zenoh_config(None)
            .map_err(setup)?;
        let session = roam_runtime::session::open(config).await.map_err(setup)?;
        let client = PlannerClient::new(session.clone(), &stack.root);
        let request = PlanRequest {
            request_id: None,
            cancel_token: None,
            start: START,
            goal: GOAL,
            t_exec_s: budget,
            deadline_s: 60.0,
            model: PlannerModel::Model1,
            params: GaOverrides {
                max_generations: Some(20),
                ..GaOverrides::default()
            },
            seed: 5,
            map_version: None,
            shortest: ShortestPathUse::Omit,
            seed_route: Vec::new(),
        };
        let never = AtomicBool::new(false);
        let (mut local, mut remote) = (Vec::new(), Vec::new());
        for run in 0..runs {
            let started = Instant::now();
            plan(
                world,
                &spec(PlannerModel::Model1, budget, 5, 20),
                &never,
                |_, _| {},
            )
            .map_err(setup)?;
            local.push(ms(started.elapsed()));
            let started = Instant::now();
            client.plan(&request).await?;
            remote.push(ms(started.elapsed()));
            progress(Done::of("round trips", "round trips", run + 1, runs));
        }
        let _ = session.close().await;
        Ok::<f64, BenchError>(median(&mut remote) - median(&mut local))
    }
    .await;
    stack.shutdown().await.map_err(setup)?;
    result
}
