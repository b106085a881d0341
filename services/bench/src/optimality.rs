//! `roam bench planner --optimality`: how far roam's plans are from the best possible.
//!
//! On seeded instances small enough to solve exactly (10 × 10 planning cells at 0.2 m,
//! a few walls, information in blobs of 0–100, start and goal in opposite corners,
//! budgets of 1.5, 2 and 3 times the fastest path's ETA: about 15 to 30 moves), the
//! greedy planner, the GA (Model I, 2000 generations) and the anytime portfolio (the
//! greedy answer, then the GA seeded with it) each plan at the executive's default
//! deadline (1 s), and the exact search (`roam_planner::exact`, branch and
//! bound, both plans as its first incumbents) finds the path that sees the most
//! distinct information within the budget. Both sides are measured on the same
//! objective, the distinct information Σ I over the cells the path perceives (what the
//! planners' reports call information); the planners optimize Model I's F_1, so the
//! share includes what that choice costs. An instance whose search hit the node limit
//! is reported as not proven: its "optimum" is then the best found, and the share an
//! upper bound.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use roam_planner::exact::{best_path, ExactAnswer};
use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::map::{GridMeta, Origin};
use roam_proto::planner::PlannerModel;
use roam_world::grid::Grid;
use roam_world::seed::{labelled, splitmix64};
use serde::Serialize;

use crate::{setup, BenchError};
use roam_experiments::progress::{Done, Progress};

/// Cells per side of an instance.
pub const SIDE: u32 = 10;

/// The planners' deadline, seconds: the executive's default `plan_deadline_s`.
pub const DEADLINE_S: f64 = 1.0;

/// Budgets as multiples of the fastest path's ETA.
pub const BUDGET_FACTORS: [f64; 3] = [1.5, 2.0, 3.0];

/// The goal: roam's plans hold at least this median share of the optimum…
pub const GOAL_MEDIAN_SHARE: f64 = 0.97;
/// …and at least this share on every instance, over at least [`GOAL_MIN_INSTANCES`]
/// proven ones.
pub const GOAL_WORST_SHARE: f64 = 0.90;
pub const GOAL_MIN_INSTANCES: usize = 30;

/// Nodes the exact search may expand per instance.
pub const NODE_LIMIT: u64 = 20_000_000;

/// One instance: the planners' plans and the optimum, in distinct information.
#[derive(Debug, Clone, Serialize)]
pub struct Instance {
    pub seed: u64,
    pub budget_factor: f64,
    pub t_exec_s: f64,
    pub optimum: f64,
    pub proven: bool,
    pub exact_nodes: u64,
    pub exact_s: f64,
    pub greedy: f64,
    pub greedy_share: f64,
    pub greedy_ms: f64,
    pub model1: f64,
    pub model1_share: f64,
    pub model1_ms: f64,
    pub anytime: f64,
    pub anytime_share: f64,
    pub anytime_ms: f64,
    /// What produced the anytime plan (`greedy`, `ga`, …).
    pub anytime_found_by: &'static str,
}

#[derive(Debug, Clone, Serialize)]
pub struct OptimalityBench {
    pub instances: Vec<Instance>,
    pub proven: usize,
    /// Median and worst share of the optimum, over the proven instances.
    pub greedy_share_median: f64,
    pub greedy_share_min: f64,
    pub model1_share_median: f64,
    pub model1_share_min: f64,
    pub anytime_share_median: f64,
    pub anytime_share_min: f64,
    /// The best of the two planners' shares, per instance: what a portfolio would get.
    pub best_of_both_share_median: f64,
    pub deadline_s: f64,
    pub objective: &'static str,
    /// Whether Model I (the executive's default) and the anytime portfolio meet the
    /// goal ([`GOAL_MEDIAN_SHARE`], [`GOAL_WORST_SHARE`], [`GOAL_MIN_INSTANCES`]),
    /// computed from the shares above.
    pub goal_met_model1: bool,
    pub goal_met_anytime: bool,
}

/// Instance `seed`: walls and information blobs on a [`SIDE`]² grid at 0.2 m.
pub fn instance_world(seed: u64) -> Result<World, BenchError> {
    let n = (SIDE * SIDE) as usize;
    let mut state = labelled(seed, "bench/optimality");
    let mut next = move |modulo: u64| {
        state = splitmix64(state);
        state % modulo
    };
    let meta = GridMeta {
        width: SIDE,
        height: SIDE,
        resolution: 0.2,
        origin: Origin::default(),
    };
    // Three blobs of interest; every cell takes the strongest at its distance.
    let blobs: Vec<(f64, f64, f64)> = (0..3)
        .map(|_| {
            (
                next(u64::from(SIDE)) as f64,
                next(u64::from(SIDE)) as f64,
                40.0 + next(61) as f64,
            )
        })
        .collect();
    let information = (0..n)
        .map(|i| {
            let (x, y) = ((i % SIDE as usize) as f64, (i / SIDE as usize) as f64);
            blobs
                .iter()
                .map(|&(bx, by, peak)| peak * (-((x - bx).powi(2) + (y - by).powi(2)) / 6.0).exp())
                .fold(0.0, f64::max)
                .round() as u8
        })
        .collect();
    // Two short walls, never on the corners where start and goal stand.
    let mut occupancy = vec![0i8; n];
    for _ in 0..2 {
        let (x, y) = (1 + next(u64::from(SIDE) - 2), 1 + next(u64::from(SIDE) - 2));
        let vertical = next(2) == 0;
        for k in 0..3 {
            let (wx, wy) = if vertical { (x, y + k) } else { (x + k, y) };
            if wx < u64::from(SIDE) - 1 && wy < u64::from(SIDE) - 1 {
                occupancy[(wy * u64::from(SIDE) + wx) as usize] = 100;
            }
        }
    }
    World::new(
        &Grid {
            meta,
            cells: occupancy,
        },
        &Grid {
            meta,
            cells: information,
        },
        roam_planner::maps::DEFAULT_COMPRESSION,
    )
    .map_err(setup)
}

/// Runs the benchmark over `instances` seeds × [`BUDGET_FACTORS`].
pub fn optimality(instances: u64, progress: Progress<'_>) -> Result<OptimalityBench, BenchError> {
    let never = AtomicBool::new(false);
    let (start, goal) = ([0.1, 0.1], [f64::from(SIDE) * 0.2 - 0.1; 2]);
    let total = instances as usize * BUDGET_FACTORS.len();
    let mut out = Vec::new();
    for seed in 0..instances {
        let world = instance_world(seed)?;
        let fastest = plan(
            &world,
            &PlanSpec::batch(start, goal, 86_400.0, PlannerModel::Shortest, 1, 0),
            &never,
            |_, _| {},
        )
        .map_err(setup)?;
        for factor in BUDGET_FACTORS {
            let t_exec_s = factor * fastest.t_eta_s;
            let run = |model: PlannerModel, generations: u32| {
                let spec = PlanSpec {
                    deadline_s: DEADLINE_S,
                    ..PlanSpec::batch(start, goal, t_exec_s, model, generations, seed)
                };
                let started = Instant::now();
                let outcome = plan(&world, &spec, &never, |_, _| {}).map_err(setup)?;
                Ok::<_, BenchError>((outcome, started.elapsed().as_secs_f64() * 1e3))
            };
            let (greedy, greedy_ms) = run(PlannerModel::Greedy, 1)?;
            let (model1, model1_ms) = run(PlannerModel::Model1, 2000)?;
            let (anytime, anytime_ms) = run(PlannerModel::Anytime, 2000)?;
            let params = GaParams::default();
            let (s, g) = (world_cell(&world, start)?, world_cell(&world, goal)?);
            let started = Instant::now();
            let exact: ExactAnswer = best_path(
                &world,
                &params,
                s,
                g,
                t_exec_s,
                &[&greedy.path, &model1.path, &anytime.path],
                NODE_LIMIT,
            )
            .map_err(setup)?;
            let exact_s = started.elapsed().as_secs_f64();
            let value = |o: &roam_planner::plan::PlanOutcome| {
                if o.within_budget {
                    roam_planner::exact::score(&world, &params, &o.path).0
                } else {
                    0.0
                }
            };
            let (gv, mv, av) = (value(&greedy), value(&model1), value(&anytime));
            let share = |v: f64| {
                if exact.distinct_information > 0.0 {
                    v / exact.distinct_information
                } else {
                    1.0
                }
            };
            out.push(Instance {
                seed,
                budget_factor: factor,
                t_exec_s,
                optimum: exact.distinct_information,
                proven: exact.proven,
                exact_nodes: exact.nodes,
                exact_s,
                greedy: gv,
                greedy_share: share(gv),
                greedy_ms,
                model1: mv,
                model1_share: share(mv),
                model1_ms,
                anytime: av,
                anytime_share: share(av),
                anytime_ms,
                anytime_found_by: anytime.source.as_str(),
            });
            progress(Done::of("instances", "instances", out.len(), total));
        }
    }
    let proven: Vec<&Instance> = out.iter().filter(|i| i.proven).collect();
    let stat = |f: &dyn Fn(&Instance) -> f64| {
        let mut v: Vec<f64> = proven.iter().map(|i| f(i)).collect();
        v.sort_by(f64::total_cmp);
        (
            v.get(v.len() / 2).copied().unwrap_or(f64::NAN),
            v.first().copied().unwrap_or(f64::NAN),
        )
    };
    let (greedy_median, greedy_min) = stat(&|i| i.greedy_share);
    let (model1_median, model1_min) = stat(&|i| i.model1_share);
    let (both_median, _) = stat(&|i| i.greedy_share.max(i.model1_share));
    let (anytime_median, anytime_min) = stat(&|i| i.anytime_share);
    let goal = |median: f64, worst: f64| {
        proven.len() >= GOAL_MIN_INSTANCES
            && median >= GOAL_MEDIAN_SHARE
            && worst >= GOAL_WORST_SHARE
    };
    Ok(OptimalityBench {
        goal_met_model1: goal(model1_median, model1_min),
        goal_met_anytime: goal(anytime_median, anytime_min),
        proven: proven.len(),
        instances: out,
        greedy_share_median: greedy_median,
        greedy_share_min: greedy_min,
        model1_share_median: model1_median,
        model1_share_min: model1_min,
        anytime_share_median: anytime_median,
        anytime_share_min: anytime_min,
        best_of_both_share_median: both_median,
        deadline_s: DEADLINE_S,
        objective: "distinct information: sum of I over the cells the path perceives (Eq. 3's window), within t_exec (Eq. 2)",
    })
}

fn world_cell(world: &World, at: [f64; 2]) -> Result<roam_planner::world::Cell, BenchError> {
    world
        .cell_at(at[0], at[1])
        .ok_or_else(|| BenchError::Setup(format!("({}, {}) is off the instance", at[0], at[1])))
}
