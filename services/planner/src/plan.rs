//! One plan end to end: check the request and its size against the limits
//! ([`crate::limits`]), find the shortest path (to refuse what cannot work), run the
//! chosen planner, measure the result.

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use roam_proto::planner::{FitnessTerms, PlannerModel, StopReason};
use roam_proto::{ErrorCode, ErrorReply};

use crate::curiosity::{Evaluator, Model};
use crate::eta::path_eta;
use crate::ga::{self, GaOptions, Problem};
use crate::limits::{self, LimitError, PlanLimits};
use crate::metrics::{path_metrics, PathMetrics};
use crate::params::{GaParams, ParamError};
use crate::search::{distance_field, shortest_path};
use crate::world::{Cell, World};

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
        }
    }
}

/// A plan before it becomes a message.
#[derive(Debug, Clone)]
pub struct PlanOutcome {
    pub path: Vec<Cell>,
    pub t_eta_s: f64,
    pub reaches_goal: bool,
    pub within_budget: bool,
    pub fitness: FitnessTerms,
    pub metrics: PathMetrics,
    pub generations: u32,
    pub evaluations: u64,
    pub planning: Duration,
    pub stop_reason: StopReason,
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

/// Plans on `world`. `progress` gets each generation's best fitness; `cancel` stops
/// the GA early (the best path so far is returned).
pub fn plan(
    world: &World,
    spec: &PlanSpec,
    cancel: &AtomicBool,
    progress: impl FnMut(u32, f64),
) -> Result<PlanOutcome, PlanError> {
    let started = Instant::now();
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
    let shortest = shortest_path(world, start, goal).ok_or(PlanError::NoPath)?;
    let needed = path_eta(world, params, &shortest);
    if needed > spec.t_exec_s {
        return Err(PlanError::BudgetTooShort {
            given_s: spec.t_exec_s,
            needed_s: needed,
            short_by_s: needed - spec.t_exec_s,
        });
    }
    let (path, evaluation, generations, evaluations, stop_reason) = match Model::of(spec.model) {
        None => {
            // The baseline's fitness terms are scored with Model I, the paper's best,
            // so that they compare with the curious plans.
            let mut evaluator = Evaluator::new(world, params, Model::Novelty, goal, spec.t_exec_s);
            let evaluation = evaluator.evaluate(&shortest);
            (shortest, evaluation, 0, 1, StopReason::Complete)
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
            let problem = Problem {
                world,
                params,
                model,
                start,
                goal,
                t_exec: spec.t_exec_s,
                goal_field: &field,
                seed_paths: std::slice::from_ref(&shortest),
            };
            let options = GaOptions {
                seed: spec.seed,
                deadline: Some(started + Duration::from_secs_f64(spec.deadline_s)),
                cap_walks_by_budget: true,
                complete_walks_to_goal: true,
                // The shortest path is in the first population; it fits the budget, so
                // the bound holds it (the max only guards rounding).
                max_path_cells: size
                    .map_or(world.cell_count(), |s| s.path_cells)
                    .max(shortest.len()),
                threads: spec.threads,
            };
            let result = ga::run(&problem, &options, cancel, progress);
            (
                result.best,
                result.evaluation,
                result.generations,
                result.evaluations,
                result.stop_reason,
            )
        }
    };
    let metrics = path_metrics(world, params, &path);
    Ok(PlanOutcome {
        t_eta_s: evaluation.t_eta,
        reaches_goal: evaluation.reaches_goal,
        within_budget: evaluation.t_eta <= spec.t_exec_s,
        fitness: evaluation.fitness,
        metrics,
        path,
        generations,
        evaluations,
        planning: started.elapsed(),
        stop_reason,
    })
}
