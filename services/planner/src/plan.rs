//! One plan end to end: check the request and its size against the limits
//! ([`crate::limits`]), find the fastest path (Eq. 2, to refuse what cannot work), seed the
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
use roam_proto::{number, Cause, ErrorCode, ErrorReply};

use crate::best::{ranked, PlanSource, Scored};
use crate::curiosity::{Evaluation, Evaluator, Model};
use crate::eta::path_eta;
use crate::ga::{self, GaOptions, Problem};
use crate::greedy::{self, GreedyProblem};
use crate::limits::{self, LimitError, PlanLimits, PlanSize};
use crate::metrics::{path_metrics, PathMetrics};
use crate::params::{GaParams, ParamError};
use crate::resolution::{self, Anchor, FineCell};
use crate::search::{distance_field, fastest_path, shortest_path};
use crate::seeds::{self, SeedProblem, ViaSeeds};
use crate::world::{Cell, World, MOVES};
use roam_world::param::check_param;

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
    /// budget did not fit the fastest path and the spec asked for the fallback.
    pub model: PlannerModel,
    /// The planned path on the planning grid (the world's cells).
    pub path: Vec<Cell>,
    /// The path the robot drives, in map cells `[x, y]`: `path` itself at the map's
    /// resolution, else its refinement on the map's cells ([`crate::resolution::refine`]).
    pub cells: Vec<[u32; 2]>,
    /// The centres of `cells` in world metres.
    pub points: Vec<[f64; 2]>,
    /// The planning grid's resolution, metres.
    pub planning_resolution_m: f64,
    /// Eq. 2 on the path the robot drives (`cells`).
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
    /// The fastest path (the floor the budget was checked against, what `model:
    /// shortest` answers; found for every plan, [`check`]) as the robot would drive it,
    /// when the spec asked for it (its `shortest` is not [`ShortestPathUse::Omit`]).
    pub shortest: Option<ShortestOutcome>,
}

/// The fastest path of a plan, measured as the plan is.
#[derive(Debug, Clone)]
pub struct ShortestOutcome {
    /// On the planning grid.
    pub path: Vec<Cell>,
    /// As driven: map cells `[x, y]` (as [`PlanOutcome::cells`]) and their centres.
    pub cells: Vec<[u32; 2]>,
    pub points: Vec<[f64; 2]>,
    /// Paper 000 Eq. 2 on `cells` under the spec's time model, seconds.
    pub t_eta_s: f64,
    /// On the planning cells it passes through.
    pub metrics: PathMetrics,
}

/// Why a plan was refused. Each says what to change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("the {which} ({}, {}) is off the map, which spans x {x0}..{x1} and y {y0}..{y1} m", number(*.x), number(*.y))]
    OffMap {
        which: &'static str,
        x: f64,
        y: f64,
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
    },
    #[error("the {which} ({}, {}) is inside an obstacle or its inflation (or unknown space); move it to free space", number(*.x), number(*.y))]
    Blocked { which: &'static str, x: f64, y: f64 },
    #[error("there is no path from the start to the goal on this map")]
    NoPath,
    #[error("the {which} ({}, {}) is free on the map but in a pocket of free space that no planning cell reaches (its planning cell's free space is elsewhere, behind an obstacle thinner than a planning cell, and no neighbouring planning cell touches it); move it, or plan at a finer planning_resolution_m", number(*.x), number(*.y))]
    Pocket { which: &'static str, x: f64, y: f64 },
    #[error("the start ({}, {}) is also the goal, so the plan is a round trip, but no legal move leaves the start's cell (its 8 neighbours are obstacles, their inflation, or corners that cannot be cut): no loop fits any t_exec_s; move the start to open floor, or ask model shortest to stay", number(*.x), number(*.y))]
    Enclosed { x: f64, y: f64 },
    #[error("the budget t_exec = {given_s:.1} s is {short_by_s:.1} s shorter than the fastest path's ETA of {needed_s:.1} s (Eq. 2, turns counted); give at least {needed_s:.1} s")]
    BudgetTooShort {
        given_s: f64,
        needed_s: f64,
        short_by_s: f64,
    },
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error(transparent)]
    Limit(#[from] LimitError),
}

impl PlanError {
    pub fn to_reply(&self) -> ErrorReply {
        let message = self.to_string();
        let end = |which: &str, start: Cause, goal: Cause| {
            let cause = if which == "start" { start } else { goal };
            ErrorReply::new(ErrorCode::InvalidRequest, message.clone()).with_cause(cause)
        };
        match self {
            PlanError::NoPath => {
                ErrorReply::new(ErrorCode::NotFound, message).with_cause(Cause::NoPath)
            }
            PlanError::OffMap { which, .. } => end(which, Cause::StartOffMap, Cause::GoalOffMap),
            PlanError::Blocked { which, .. } => end(which, Cause::StartBlocked, Cause::GoalBlocked),
            // Free, but joined to nothing: no path, whichever end it is.
            PlanError::Pocket { .. } | PlanError::Enclosed { .. } => {
                ErrorReply::new(ErrorCode::InvalidRequest, message).with_cause(Cause::NoPath)
            }
            PlanError::Limit(limit) => {
                let (max, actual) = limit.max_actual();
                ErrorReply::limit(limit.name(), max, actual, message)
            }
            PlanError::Param(ParamError { name, value, .. })
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

/// How far a start inside an obstacle or its inflation moves to the nearest free cell,
/// metres. A robot pushed aside by a cart or a walker, or stopped beside what the fleet
/// saw ([`crate::seen`]), stands in inflation it can drive out of; refusing to plan from
/// there would leave it where it is. A start farther in is refused.
pub const START_SNAP_M: f64 = 0.5;

/// The free cell nearest (by distance, ties to the lower index) to `at` within `radius`
/// cells on a `width × height` grid indexed `y · width + x`.
fn nearest_free(
    width: usize,
    height: usize,
    radius: usize,
    at: usize,
    is_free: impl Fn(usize) -> bool,
) -> Option<usize> {
    let (ax, ay) = ((at % width) as i64, (at / width) as i64);
    let r = radius as i64;
    let mut best: Option<(i64, usize)> = None;
    for y in (ay - r).max(0)..=(ay + r).min(height as i64 - 1) {
        for x in (ax - r).max(0)..=(ax + r).min(width as i64 - 1) {
            let d2 = (x - ax).pow(2) + (y - ay).pow(2);
            let c = (y * width as i64 + x) as usize;
            if d2 <= r * r && is_free(c) && best.is_none_or(|(b, i)| (d2, c) < (b, i)) {
                best = Some((d2, c));
            }
        }
    }
    best.map(|(_, c)| c)
}

/// Where a start or goal is: its planning cell, and on a world at a coarser planning
/// resolution how its map cell joins that cell ([`crate::resolution::locate`]).
fn locate(
    world: &World,
    which: &'static str,
    [x, y]: [f64; 2],
) -> Result<(Cell, Option<Anchor>), PlanError> {
    let meta = world.fine.as_ref().map_or(world.meta, |f| f.meta);
    let off = || PlanError::OffMap {
        which,
        x,
        y,
        x0: meta.origin.x,
        x1: meta.origin.x + f64::from(meta.width) * meta.resolution,
        y0: meta.origin.y,
        y1: meta.origin.y + f64::from(meta.height) * meta.resolution,
    };
    let blocked = || PlanError::Blocked { which, x, y };
    // Only a start moves: a goal in an obstacle is the task's to fix.
    let snap_m = if which == "start" { START_SNAP_M } else { 0.0 };
    let Some(fine) = &world.fine else {
        let mut cell = world.cell_at(x, y).ok_or_else(off)?;
        if !world.is_traversable(cell) {
            let (w, h) = (world.width(), world.height());
            let radius = (snap_m / world.meta.resolution).floor() as usize;
            cell = nearest_free(w, h, radius, cell as usize, |c| {
                world.is_traversable(c as Cell)
            })
            .ok_or_else(blocked)? as Cell;
        }
        return Ok((cell, None));
    };
    let mut cell = fine.cell_at(x, y).ok_or_else(off)?;
    if !fine.is_free(cell) {
        let radius = (snap_m / fine.meta.resolution).floor() as usize;
        cell = nearest_free(fine.width(), fine.height(), radius, cell as usize, |c| {
            fine.is_free(c as FineCell)
        })
        .ok_or_else(blocked)? as FineCell;
    }
    let anchor = resolution::locate(fine, world, cell).ok_or(PlanError::Pocket { which, x, y })?;
    Ok((anchor.cell, Some(anchor)))
}

/// Checks a request's numbers before any work.
pub fn check_spec(spec: &PlanSpec) -> Result<(), PlanError> {
    let range = |name, value: f64, max: f64, range| {
        check_param(name, value, value > 0.0 && value <= max, range)
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
        check_param("start/goal", *v, true, "finite world coordinates in metres")?;
    }
    spec.params.validate()?;
    Ok(())
}

/// The work of a plan, for the service's queue ([`work`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Work {
    /// Its GA's cost ([`crate::limits`], counting the generations that can start before
    /// its deadline; for `greedy` its evaluations of a longest path; 0 for the baseline).
    pub cost: u64,
    /// The generations `cost` counts: the request's max_generations, or the fewer that
    /// can start before the deadline ([`limits::generations_before_deadline`]). The
    /// request's for `greedy` and the baseline.
    pub generations: u32,
}

/// The work of a plan, for the service's queue, or the limit it exceeds.
pub fn work(world: &World, spec: &PlanSpec) -> Result<Work, PlanError> {
    let requested = spec.params.max_generations;
    let work = match Model::of(spec.model) {
        Some(_) => {
            let size = size(world, spec)?;
            if spec.model == PlannerModel::Greedy {
                Work {
                    cost: (size.path_cells as u64).saturating_mul(greedy::WORK_EVALUATIONS),
                    generations: requested,
                }
            } else {
                Work {
                    cost: size.cost,
                    generations: size.generations,
                }
            }
        }
        None => Work {
            cost: 0,
            generations: requested,
        },
    };
    Ok(work)
}

/// The GA's size ([`limits::check`]): the work that can be done before the deadline
/// on the spec's evaluation threads.
fn size(world: &World, spec: &PlanSpec) -> Result<PlanSize, LimitError> {
    limits::check(
        &sized_params(spec),
        world.meta.resolution,
        spec.t_exec_s,
        world.cell_count(),
        spec.deadline_s * spec.threads.max(1) as f64,
        &spec.limits,
    )
}

/// The parameters a plan is sized by ([`crate::limits`]): the request's, except that
/// the greedy planner has no population or generations (one route at a time).
fn sized_params(spec: &PlanSpec) -> GaParams {
    if spec.model == PlannerModel::Greedy {
        GaParams {
            population: 1,
            max_generations: 1,
            ..spec.params.clone()
        }
    } else {
        spec.params.clone()
    }
}

/// A request that passed every check before planning.
struct Checked {
    start: Cell,
    goal: Cell,
    /// The path of least Eq. 2 time ([`fastest_path`]): the floor every budget is
    /// checked against, and what the `shortest` baseline returns.
    fastest: Vec<Cell>,
    /// Its Eq. 2 time as driven, and whether the budget fits it (it does unless the
    /// spec asked for the fastest path as a fallback).
    fastest_t_eta_s: f64,
    budget_fits: bool,
    /// The path the GA's first population holds and [`best_of`] never falls below: the
    /// distance-shortest path when it fits the budget (as before issue 16, so plans
    /// whose budget admits it are unchanged bit for bit), else the fastest path.
    shortest: Vec<Cell>,
    /// The GA's size; `None` for the baseline.
    size: Option<PlanSize>,
    /// On a world at a coarser planning resolution: how the start and goal join the
    /// planning grid, and the fastest path as the robot drives it (the floor).
    anchors: Option<(Anchor, Anchor)>,
    fastest_driven: Option<Vec<FineCell>>,
    /// The budget the planning grid plans with: t_exec less what driving the fastest
    /// path on the map's cells takes beyond its planning-grid ETA (the legs to and from
    /// the start's and goal's map cells), so that plans fit when driven. t_exec itself
    /// at the map's resolution.
    planning_budget_s: f64,
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
    let (start, start_anchor) = locate(world, "start", spec.start)?;
    let (goal, goal_anchor) = locate(world, "goal", spec.goal)?;
    let params = &spec.params;
    // The GA's size, before any search: the baseline has no population to bound.
    let size = match Model::of(spec.model) {
        Some(_) => Some(size(world, spec)?),
        None => None,
    };
    if start == goal && size.is_some() && (0..MOVES.len()).all(|d| world.step(start, d).is_none()) {
        return Err(PlanError::Enclosed {
            x: spec.start[0],
            y: spec.start[1],
        });
    }
    let fastest = fastest_path(world, params, start, goal).ok_or(PlanError::NoPath)?;
    let planned_eta = path_eta(world, params, &fastest);
    let (needed, fastest_driven, anchors) = match (&world.fine, start_anchor, goal_anchor) {
        (Some(fine), Some(a), Some(b)) => {
            let driven =
                resolution::refine(fine, params, &fastest, &a, &b).ok_or(PlanError::NoPath)?;
            (fine.eta(params, &driven), Some(driven), Some((a, b)))
        }
        _ => (planned_eta, None, None),
    };
    let planning_budget_s = spec.t_exec_s - (needed - planned_eta).max(0.0);
    let budget_fits = needed <= spec.t_exec_s;
    if !budget_fits && spec.shortest != ShortestPathUse::Fallback {
        return Err(PlanError::BudgetTooShort {
            given_s: spec.t_exec_s,
            needed_s: needed,
            short_by_s: needed - spec.t_exec_s,
        });
    }
    let shortest = match size {
        Some(_) => match shortest_path(world, start, goal) {
            Some(path) if path_eta(world, params, &path) <= planning_budget_s => path,
            _ => fastest.clone(),
        },
        None => fastest.clone(),
    };
    Ok(Checked {
        start,
        goal,
        fastest,
        fastest_t_eta_s: needed,
        budget_fits,
        shortest,
        size,
        anchors,
        fastest_driven,
        planning_budget_s,
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
        t_exec: checked.planning_budget_s,
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
    // A budget the fastest path does not fit (asked for as a fallback): the fastest
    // path answers, as the baseline would.
    let model = if checked.budget_fits {
        spec.model
    } else {
        PlannerModel::Shortest
    };
    let budget = checked.planning_budget_s;
    let world_for_model;
    let world = if Model::of(model) == Some(Model::Heterogeneity)
        && params.heuristic_compression != world.heuristic_compression
    {
        let mut w = world.clone();
        w.set_heuristic_compression(params.heuristic_compression);
        world_for_model = w;
        &world_for_model
    } else {
        world
    };
    let (ranked, scoring, generations, (evaluations, evaluated_genes), stop_reason, via_seeds) =
        match Model::of(model) {
            None => {
                // The baseline's fitness terms are scored with Model I, the paper's best,
                // so that they compare with the curious plans.
                let mut evaluator = Evaluator::new(world, params, Model::Novelty, goal, budget);
                let evaluation = evaluator.evaluate(&checked.fastest);
                let genes = checked.fastest.len() as u64;
                let chosen = Scored {
                    path: checked.fastest.clone(),
                    evaluation,
                    source: PlanSource::Shortest,
                };
                let ranked = vec![chosen];
                (
                    ranked,
                    Model::Novelty,
                    0,
                    (1, genes),
                    StopReason::Complete,
                    0,
                )
            }
            Some(_) if model == PlannerModel::Greedy => {
                let field = distance_field(world, goal);
                let problem = GreedyProblem {
                    world,
                    params,
                    start,
                    goal,
                    t_exec: budget,
                    floor: &checked.shortest,
                    goal_field: &field,
                };
                let result = greedy::run(&problem, deadline, cancel);
                let mut progress = progress;
                progress(result.rounds, result.evaluation.fitness.total);
                let stop_reason = match (result.interrupted, cancel.load(Ordering::Relaxed)) {
                    (false, _) => StopReason::Complete,
                    (true, true) => StopReason::Cancelled,
                    (true, false) => StopReason::Deadline,
                };
                let found = Scored {
                    path: result.path,
                    evaluation: result.evaluation,
                    source: PlanSource::Ga,
                };
                let mut evaluator = Evaluator::new(world, params, Model::Novelty, goal, budget);
                (
                    ranked(&mut evaluator, found, &checked.shortest, &[]),
                    Model::Novelty,
                    result.rounds,
                    (result.evaluations, result.evaluated_genes),
                    stop_reason,
                    0,
                )
            }
            Some(model) => {
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
                    t_exec: budget,
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
                let ranked = if strict {
                    vec![ga]
                } else {
                    let mut evaluator = Evaluator::new(world, params, model, goal, budget);
                    ranked(&mut evaluator, ga, &checked.shortest, &seed_paths[1..])
                };
                (
                    ranked,
                    model,
                    result.generations,
                    (result.evaluations, result.evaluated_genes),
                    result.stop_reason,
                    via_seeds,
                )
            }
        };
    let driven = drive(world, spec, &checked, scoring, ranked);
    let shortest = (spec.shortest != ShortestPathUse::Omit)
        .then(|| fastest_as_driven(world, params, &checked));
    Ok(PlanOutcome {
        model,
        t_eta_s: driven.t_eta_s,
        reaches_goal: driven.chosen.evaluation.reaches_goal,
        within_budget: driven.t_eta_s <= spec.t_exec_s,
        fitness: driven.chosen.evaluation.fitness,
        metrics: driven.metrics,
        path: driven.chosen.path,
        cells: driven.cells,
        points: driven.points,
        planning_resolution_m: world.meta.resolution,
        generations,
        evaluations,
        evaluated_genes,
        planning: started.elapsed(),
        stop_reason,
        source: driven.chosen.source,
        via_seeds,
        shortest,
    })
}

/// [`ShortestOutcome`] of a checked request: its fastest path as driven, measured as
/// the `shortest` baseline measures it.
fn fastest_as_driven(world: &World, params: &GaParams, checked: &Checked) -> ShortestOutcome {
    match (&world.fine, &checked.fastest_driven) {
        (Some(fine), Some(driven)) => {
            let path = fine.planning_cells(driven);
            ShortestOutcome {
                metrics: path_metrics(world, params, &path),
                path,
                cells: fine.grid_cells(driven),
                points: fine.centers(driven),
                t_eta_s: checked.fastest_t_eta_s,
            }
        }
        _ => ShortestOutcome {
            metrics: path_metrics(world, params, &checked.fastest),
            path: checked.fastest.clone(),
            cells: world.grid_cells(&checked.fastest),
            points: world.centers(&checked.fastest),
            t_eta_s: checked.fastest_t_eta_s,
        },
    }
}

/// The plan as the robot drives it.
struct Driven {
    chosen: Scored,
    t_eta_s: f64,
    metrics: PathMetrics,
    cells: Vec<[u32; 2]>,
    points: Vec<[f64; 2]>,
}

/// How many of the fittest candidates are driven on the map's cells, at most, before
/// falling back on the fastest path (each is one search of at most `L · k² · 9` states).
pub const MAX_DRIVEN_CANDIDATES: usize = 8;

/// The fittest candidate, as driven. At the map's resolution that is `ranked[0]` as it
/// is. At a coarser planning resolution each candidate, fittest first, is refined onto
/// the map's cells ([`resolution::refine`]) until one fits t_exec when driven (Eq. 2 on
/// the map's cells); the fastest path, which the budget was checked against as driven,
/// is the last resort. Its fitness is scored on the planning cells the driven path
/// passes through, with the time terms (Eqs. 4, 6, 7) of the driven t_ETA, and U_ges,
/// D and the distinct information on those planning cells (Eqs. 11, 12).
fn drive(
    world: &World,
    spec: &PlanSpec,
    checked: &Checked,
    model: Model,
    ranked: Vec<Scored>,
) -> Driven {
    let params = &spec.params;
    let (Some(fine), Some((start, goal)), Some(fastest)) =
        (&world.fine, &checked.anchors, &checked.fastest_driven)
    else {
        let chosen = ranked.into_iter().next().unwrap_or_else(|| Scored {
            path: checked.fastest.clone(),
            evaluation: Evaluator::new(world, params, model, checked.goal, spec.t_exec_s)
                .evaluate(&checked.fastest),
            source: PlanSource::Shortest,
        });
        return Driven {
            t_eta_s: chosen.evaluation.t_eta,
            metrics: path_metrics(world, params, &chosen.path),
            cells: world.grid_cells(&chosen.path),
            points: world.centers(&chosen.path),
            chosen,
        };
    };
    let (path, source) = ranked
        .iter()
        .take(MAX_DRIVEN_CANDIDATES)
        .find_map(|candidate| {
            let driven = resolution::refine(fine, params, &candidate.path, start, goal)?;
            (fine.eta(params, &driven) <= spec.t_exec_s).then_some((driven, candidate.source))
        })
        .unwrap_or_else(|| (fastest.clone(), PlanSource::Shortest));
    let t_eta_s = fine.eta(params, &path);
    let planned = fine.planning_cells(&path);
    let mut evaluator = Evaluator::new(world, params, model, checked.goal, spec.t_exec_s);
    let evaluation = with_driven_time(evaluator.evaluate(&planned), t_eta_s, params, spec.t_exec_s);
    Driven {
        metrics: path_metrics(world, params, &planned),
        cells: fine.grid_cells(&path),
        points: fine.centers(&path),
        t_eta_s,
        chosen: Scored {
            path: planned,
            evaluation,
            source,
        },
    }
}

/// An evaluation with its time terms (Eqs. 4, 6, 7) recomputed for the driven t_ETA.
fn with_driven_time(mut e: Evaluation, t: f64, params: &GaParams, t_exec: f64) -> Evaluation {
    let f = &mut e.fitness;
    f.f2_on_time = if t < t_exec { params.w2 } else { 0.0 };
    f.f4_overtime = -params.w4 * (t - t_exec).max(0.0);
    f.f5_idle = -params.w5 * (t_exec - t).max(0.0);
    f.total = f.f1_information
        + f.f2_on_time
        + f.f3_goal
        + f.f4_overtime
        + f.f5_idle
        + f.f6_localizability;
    e.t_eta = t;
    e
}
