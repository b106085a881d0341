//! What a plan is asked for, what it gives, and why it is refused: the types of the
//! plan contract ([`PlanSpec`], [`PlanOutcome`], [`PlanError`]) and the checks of a
//! request's numbers that need no map ([`check_spec`]).

use std::time::Duration;

use roam_proto::planner::{FitnessTerms, PlannerModel, ShortestPathUse, StopReason};
use roam_proto::{number, Cause, ErrorCode, ErrorReply};
use roam_world::param::check_param;

use crate::best::PlanSource;
use crate::limits::{LimitError, PlanLimits};
use crate::metrics::PathMetrics;
use crate::params::{GaParams, ParamError};
use crate::world::Cell;

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
    /// A replan's warm start: the route the robot drives now, world metres
    /// ([`roam_proto::planner::PlanRequest::seed_route`], [`crate::remainder`]).
    pub seed_route: Vec<[f64; 2]>,
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
            seed_route: Vec::new(),
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
    /// With a seed route: whether it was joined to the planning grid and planned from
    /// ([`crate::remainder`]); `None` without one.
    pub seed_route_used: Option<bool>,
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
    /// A short token for what was refused, for counting refusals by kind (a batch's
    /// report); the message says it to a person.
    pub fn kind(&self) -> &'static str {
        match self {
            PlanError::OffMap { which: "start", .. } => "start_off_map",
            PlanError::OffMap { .. } => "goal_off_map",
            PlanError::Blocked { which: "start", .. } => "start_blocked",
            PlanError::Blocked { .. } => "goal_blocked",
            PlanError::NoPath => "no_path",
            PlanError::Pocket { .. } => "pocket",
            PlanError::Enclosed { .. } => "enclosed",
            PlanError::BudgetTooShort { .. } => "budget_too_short",
            PlanError::Param(_) => "parameter",
            PlanError::Limit(_) => "limit",
        }
    }

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
    let max = crate::remainder::MAX_SEED_ROUTE_POINTS;
    if spec.seed_route.len() > max {
        return Err(PlanError::Limit(LimitError::SeedRoute {
            actual: spec.seed_route.len() as u64,
            max: max as u64,
        }));
    }
    for v in spec.seed_route.iter().flatten() {
        check_param("seed_route", *v, true, "finite world coordinates in metres")?;
    }
    spec.params.validate()?;
    Ok(())
}
