//! One plan end to end: check the request and its size against the limits
//! ([`crate::limits`]), find the shortest path (to refuse what cannot work), seed the
//! first population through informative via-points ([`crate::seeds`]), run the chosen
//! planner, return the fittest of its result and the plans it was seeded with
//! ([`crate::best`]), measure the result.
//!
//! **Round trips** (start = goal: a robot whose next task is where it stands, the
//! commonest downtime of all). Nothing special is planned for them: the shortest path is
//! the one cell S, the via-point seeds are loops S → v → … → S, and random walks use
//! `walk_end_share` of the budget before they may end ([`crate::ga`]). The fitness then
//! prefers a loop within the budget to standing still, for every model: both earn F2
//! (on time, Eq. 4) and F3 (at G, Eq. 5); the loop's F1 (Eq. 3) is at least the
//! one cell's, since its first gene perceives the same window and every later gain is
//! ≥ 0 (Eqs. 8–10); and its F5 (Eq. 7) is higher by W_5 · t_ETA(loop), 10 per second
//! driven at Table I's weights. So a loop that drives t seconds wins by at least
//! W_5 · t, and by W_1 times whatever new information it sees. Standing still is the plan
//! only when no loop fits: a budget below the smallest loop's t_ETA (one cell out and
//! back, 2 · v_lin · resolution + π · v_ang: 3.9 s at Table I on 0.2 m cells), when the
//! one-cell path is the only plan on time. A start with no legal move at all is refused
//! ([`PlanError::Enclosed`]).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use roam_proto::planner::{FitnessTerms, PlannerModel, ShortestPathUse, StopReason};
use roam_proto::{ErrorCode, ErrorReply};

use crate::best::{best_of, PlanSource, Scored};
use crate::curiosity::{Evaluator, Model};
use crate::eta::path_eta;
use crate::ga::{self, GaOptions, Problem};
use crate::limits::{self, LimitError, PlanLimits, PlanSize};
use crate::metrics::{path_metrics, PathMetrics};
use crate::params::{GaParams, ParamError};
use crate::search::{distance_field, shortest_path};
use crate::seeds::{self, SeedProblem, ViaSeeds};
use crate::world::{Cell, World, MOVES};

/// The longest planning deadline a request may set.
pub const MAX_DEADLINE_S: f64 = 600.0;
/// The longest driving budget a request may set (a day).
pub const MAX_T_EXEC_S: f64 = 86_400.0;

/// What to plan.
#[derive(Debug, Clone)]
pub struct PlanSpec {
    pub start: [f64; 2],
    pub goal: [f64; 2],
    pub t_exec_s: f64,
    pub deadline_s: f64,
    pub model: PlannerModel,
    pub params: GaParams,
    pub seed: u64,
    /// Evaluation threads (see [`GaOptions::threads`]); the result does not depend on it.
    pub threads: usize,
    /// The size limits a GA plan is checked against before any work.
    pub limits: PlanLimits,
    /// Whether a budget below the shortest path's ETA is refused or answered with the
    /// shortest path ([`ShortestPathUse::Fallback`]); the outcome carries the shortest
    /// path either way, and the service attaches it to the reply unless `Omit`.
    pub shortest: ShortestPathUse,
}

impl PlanSpec {
    /// A batch-experiment spec: Table I's parameters with `max_generations`, a deadline
    /// far enough away that the generation count ends the run (so results repeat bit
    /// for bit), the default evaluation threads and the default limits.
    pub fn batch(
        start: [f64; 2],
        goal: [f64; 2],
        t_exec_s: f64,
        model: PlannerModel,
        max_generations: u32,
        seed: u64,
    ) -> PlanSpec {
        PlanSpec {
            start,
            goal,
            t_exec_s,
            deadline_s: MAX_DEADLINE_S,
            model,
            params: GaParams {
                max_generations,
                ..GaParams::default()
            },
            seed,
            threads: crate::ga::default_threads(),
            limits: PlanLimits::default(),
            shortest: ShortestPathUse::Omit,
        }
    }
}

/// A plan before it becomes a message.
#[derive(Debug, Clone)]
pub struct PlanOutcome {
    /// The model that answered: the spec's, or [`PlannerModel::Shortest`] when the
    /// budget did not fit the shortest path and the spec asked for the fallback.
    pub model: PlannerModel,
    pub path: Vec<Cell>,
    pub t_eta_s: f64,
    pub reaches_goal: bool,
    pub within_budget: bool,
    pub fitness: FitnessTerms,
    pub metrics: PathMetrics,
    pub generations: u32,
    pub evaluations: u64,
    /// Genes of all evaluated paths ([`crate::ga::GaResult::evaluated_genes`]).
    pub evaluated_genes: u64,
    pub planning: Duration,
    pub stop_reason: StopReason,
    /// Where the path comes from: the GA, or unchanged the shortest path or a seed when
    /// one of them was fitter ([`crate::best`]).
    pub source: PlanSource,
    /// The via-point seeds the first population held ([`crate::seeds`]).
    pub via_seeds: usize,
    /// The shortest path (found for every plan, [`check`]) when the spec asked for it
    /// (its `shortest` is not [`ShortestPathUse::Omit`]).
    pub shortest: Option<ShortestOutcome>,
}

/// The shortest path of a plan, measured as the plan is.
#[derive(Debug, Clone)]
pub struct ShortestOutcome {
    pub path: Vec<Cell>,
    /// Paper 000 Eq. 2 under the spec's time model, seconds.
    pub t_eta_s: f64,
    pub metrics: PathMetrics,
}

/// Why a plan was refused. Each says what to change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("the {which} ({x}, {y}) is off the map, which spans x {x0}..{x1} and y {y0}..{y1} m")]
    OffMap {
        which: &'static str,
        x: f64,
        y: f64,
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
    },
    #[error("the {which} ({x}, {y}) is inside an obstacle or its inflation (or unknown space); move it to free space")]
    Blocked { which: &'static str, x: f64, y: f64 },
    #[error("there is no path from the start to the goal on this map")]
    NoPath,
    #[error("the start ({x}, {y}) is also the goal, so the plan is a round trip, but no legal move leaves the start's cell (its 8 neighbours are obstacles, their inflation, or corners that cannot be cut): no loop fits any t_exec_s; move the start to open floor, or ask model shortest to stay")]
    Enclosed { x: f64, y: f64 },
    #[error("the budget t_exec = {given_s:.1} s is {short_by_s:.1} s shorter than the shortest path's ETA of {needed_s:.1} s; give at least {needed_s:.1} s")]
    BudgetTooShort {
        given_s: f64,
        needed_s: f64,
        short_by_s: f64,
    },
    #[error("{name} = {value} is out of range; use {range}")]
    OutOfRange {
        name: &'static str,
        value: f64,
        range: &'static str,
    },
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error(transparent)]
    Limit(#[from] LimitError),
}

impl PlanError {
    pub fn to_reply(&self) -> ErrorReply {
        let message = self.to_string();
        match self {
            PlanError::NoPath => ErrorReply::new(ErrorCode::NotFound, message),
            PlanError::Limit(limit) => {
                let (max, actual) = limit.max_actual();
                ErrorReply::limit(limit.name(), max, actual, message)
            }
            PlanError::OutOfRange { name, value, .. }
                if *name == "deadline_s" || *name == "t_exec_s" =>
            {
                let max = if *name == "deadline_s" {
                    MAX_DEADLINE_S
                } else {
                    MAX_T_EXEC_S
                };
                if *value > max {
                    ErrorReply::limit(name, max as u64, value.ceil() as u64, message)
                } else {
                    ErrorReply::new(ErrorCode::InvalidRequest, message)
                }
            }
            _ => ErrorReply::new(ErrorCode::InvalidRequest, message),
        }
    }
}

fn locate(world: &World, which: &'static str, [x, y]: [f64; 2]) -> Result<Cell, PlanError> {
    let meta = world.meta;
    let cell = world.cell_at(x, y).ok_or(PlanError::OffMap {
        which,
        x,
        y,
        x0: meta.origin.x,
        x1: meta.origin.x + f64::from(meta.width) * meta.resolution,
        y0: meta.origin.y,
        y1: meta.origin.y + f64::from(meta.height) * meta.resolution,
    })?;
    if !world.is_traversable(cell) {
        return Err(PlanError::Blocked { which, x, y });
    }
    Ok(cell)
}

/// Checks a request's numbers before any work.
pub fn check_spec(spec: &PlanSpec) -> Result<(), PlanError> {
    let range = |name, value: f64, max: f64, range| {
        if value.is_finite() && value > 0.0 && value <= max {
            Ok(())
        } else {
            Err(PlanError::OutOfRange { name, value, range })
        }
    };
    range(
        "t_exec_s",
        spec.t_exec_s,
        MAX_T_EXEC_S,
        "(0, 86400] seconds",
    )?;
    range(
        "deadline_s",
        spec.deadline_s,
        MAX_DEADLINE_S,
        "(0, 600] seconds",
    )?;
    for v in spec.start.iter().chain(&spec.goal) {
        if !v.is_finite() {
            return Err(PlanError::OutOfRange {
                name: "start/goal",
                value: *v,
                range: "finite world coordinates in metres",
            });
        }
    }
    spec.params.validate()?;
    Ok(())
}

/// A request that passed every check before planning.
struct Checked {
    start: Cell,
    goal: Cell,
    /// The shortest path, its ETA, and whether the budget fits it (it does unless the
    /// spec asked for the shortest path as a fallback).
    shortest: Vec<Cell>,
    shortest_t_eta_s: f64,
    budget_fits: bool,
    /// The GA's size; `None` for the baseline.
    size: Option<PlanSize>,
}

impl Checked {
    /// The longest chromosome. The shortest path is in the first population and fits
    /// the budget, so the bound holds it (the max only guards rounding).
    fn max_path_cells(&self, world: &World) -> usize {
        self.size
            .map_or(world.cell_count(), |s| s.path_cells)
            .max(self.shortest.len())
    }
}

/// Everything [`plan`] refuses before any work, and the shortest path: the one place
/// where "shortest" is decided, for the refusal, the GA's seed, the fallback and the
/// path attached to the reply.
fn check(world: &World, spec: &PlanSpec) -> Result<Checked, PlanError> {
    check_spec(spec)?;
    let start = locate(world, "start", spec.start)?;
    let goal = locate(world, "goal", spec.goal)?;
    let params = &spec.params;
    // The GA's size, before any search: the baseline has no population to bound.
    let size = match Model::of(spec.model) {
        Some(_) => Some(limits::check(
            params,
            world.meta.resolution,
            spec.t_exec_s,
            world.cell_count(),
            &spec.limits,
        )?),
        None => None,
    };
    if start == goal && size.is_some() && (0..MOVES.len()).all(|d| world.step(start, d).is_none()) {
        return Err(PlanError::Enclosed {
            x: spec.start[0],
            y: spec.start[1],
        });
    }
    let shortest = shortest_path(world, start, goal).ok_or(PlanError::NoPath)?;
    let needed = path_eta(world, params, &shortest);
    let budget_fits = needed <= spec.t_exec_s;
    if !budget_fits && spec.shortest != ShortestPathUse::Fallback {
        return Err(PlanError::BudgetTooShort {
            given_s: spec.t_exec_s,
            needed_s: needed,
            short_by_s: needed - spec.t_exec_s,
        });
    }
    Ok(Checked {
        start,
        goal,
        shortest,
        shortest_t_eta_s: needed,
        budget_fits,
        size,
    })
}

/// The via-point seeds [`plan`] puts in a GA's first population for `spec`
/// ([`crate::seeds`]; none for the baseline), built the same way: for tests and for
/// anyone who wants to see them.
pub fn via_seeds(world: &World, spec: &PlanSpec) -> Result<ViaSeeds, PlanError> {
    let checked = check(world, spec)?;
    if checked.size.is_none() || !checked.budget_fits {
        return Ok(ViaSeeds::default());
    }
    let field = distance_field(world, checked.goal);
    Ok(seeds_for(world, spec, &checked, &field, &|| false))
}

fn seeds_for(
    world: &World,
    spec: &PlanSpec,
    checked: &Checked,
    goal_field: &[u32],
    stop: &dyn Fn() -> bool,
) -> ViaSeeds {
    let problem = SeedProblem {
        world,
        params: &spec.params,
        start: checked.start,
        goal: checked.goal,
        t_exec: spec.t_exec_s,
        goal_field,
        max_path_cells: checked.max_path_cells(world),
    };
    seeds::via_paths(&problem, seeds::seed_count(&spec.params), spec.seed, stop)
}

/// Plans on `world`. `progress` gets each generation's best fitness; `cancel` stops
/// the GA early (the best path so far is returned).
pub fn plan(
    world: &World,
    spec: &PlanSpec,
    cancel: &AtomicBool,
    progress: impl FnMut(u32, f64),
) -> Result<PlanOutcome, PlanError> {
    let started = Instant::now();
    let checked = check(world, spec)?;
    let params = &spec.params;
    let (start, goal) = (checked.start, checked.goal);
    let deadline = started + Duration::from_secs_f64(spec.deadline_s);
    // A budget the shortest path does not fit (asked for as a fallback): the shortest
    // path answers, as the baseline would.
    let model = if checked.budget_fits {
        spec.model
    } else {
        PlannerModel::Shortest
    };
    let shortest = (spec.shortest != ShortestPathUse::Omit).then(|| ShortestOutcome {
        metrics: path_metrics(world, params, &checked.shortest),
        path: checked.shortest.clone(),
        t_eta_s: checked.shortest_t_eta_s,
    });
    let (chosen, generations, (evaluations, evaluated_genes), stop_reason, via_seeds) =
        match Model::of(model) {
            None => {
                // The baseline's fitness terms are scored with Model I, the paper's best,
                // so that they compare with the curious plans.
                let mut evaluator =
                    Evaluator::new(world, params, Model::Novelty, goal, spec.t_exec_s);
                let evaluation = evaluator.evaluate(&checked.shortest);
                let genes = checked.shortest.len() as u64;
                let chosen = Scored {
                    path: checked.shortest,
                    evaluation,
                    source: PlanSource::Shortest,
                };
                (chosen, 0, (1, genes), StopReason::Complete, 0)
            }
            Some(model) => {
                let mut world_for_model;
                let world = if model == Model::Heterogeneity
                    && params.heuristic_compression != world.heuristic_compression
                {
                    world_for_model = world.clone();
                    world_for_model.set_heuristic_compression(params.heuristic_compression);
                    &world_for_model
                } else {
                    world
                };
                let field = distance_field(world, goal);
                let stop = || cancel.load(Ordering::Relaxed) || Instant::now() >= deadline;
                // Paper 000 to the letter (GaParams::random_walks_only): random walks
                // only, nothing seeded and nothing to fall back on.
                let strict = params.random_walks_only;
                let seeds = if strict {
                    Vec::new()
                } else {
                    seeds_for(world, spec, &checked, &field, &stop).paths
                };
                let via_seeds = seeds.len();
                // The shortest path first, then the via-point seeds (see crate::ga).
                let mut seed_paths = Vec::with_capacity(1 + via_seeds);
                if !strict {
                    seed_paths.push(checked.shortest.clone());
                }
                seed_paths.extend(seeds);
                let problem = Problem {
                    world,
                    params,
                    model,
                    start,
                    goal,
                    t_exec: spec.t_exec_s,
                    goal_field: &field,
                    seed_paths: &seed_paths,
                };
                let options = GaOptions {
                    seed: spec.seed,
                    deadline: Some(deadline),
                    cap_walks_by_budget: !strict,
                    complete_walks_to_goal: !strict,
                    // The paper's walks may be as long as the map has cells (§II.A.1);
                    // roam bounds chromosomes by the budget (crate::limits). Only the
                    // reproduction sets `random_walks_only` (no request can), so the
                    // size promise to requesters holds.
                    max_path_cells: if strict {
                        checked.max_path_cells(world).max(world.traversable_count())
                    } else {
                        checked.max_path_cells(world)
                    },
                    threads: spec.threads,
                };
                let result = ga::run(&problem, &options, cancel, progress);
                let ga = Scored {
                    path: result.best,
                    evaluation: result.evaluation,
                    source: PlanSource::Ga,
                };
                let chosen = if strict {
                    ga
                } else {
                    let mut evaluator = Evaluator::new(world, params, model, goal, spec.t_exec_s);
                    best_of(&mut evaluator, ga, &checked.shortest, &seed_paths[1..])
                };
                (
                    chosen,
                    result.generations,
                    (result.evaluations, result.evaluated_genes),
                    result.stop_reason,
                    via_seeds,
                )
            }
        };
    let evaluation = chosen.evaluation;
    let metrics = path_metrics(world, params, &chosen.path);
    Ok(PlanOutcome {
        model,
        t_eta_s: evaluation.t_eta,
        reaches_goal: evaluation.reaches_goal,
        within_budget: evaluation.t_eta <= spec.t_exec_s,
        fitness: evaluation.fitness,
        metrics,
        path: chosen.path,
        generations,
        evaluations,
        evaluated_genes,
        planning: started.elapsed(),
        stop_reason,
        source: chosen.source,
        via_seeds,
        shortest,
    })
}
