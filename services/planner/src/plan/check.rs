//! Everything a plan refuses before any work, and what it learns doing so: where the
//! start and goal are (a start in inflation moved to free floor), the plan's size against
//! the limits, the fastest path every budget is checked against, the shortest path the
//! planners start from, and the budget on the planning grid ([`Checked`]).

use roam_proto::planner::{PlannerModel, ShortestPathUse};

use crate::curiosity::Model;
use crate::eta::path_eta;
use crate::greedy;
use crate::limits::{self, LimitError, PlanSize};
use crate::params::GaParams;
use crate::remainder::{self, RemainderError};
use crate::resolution::{self, Anchor, FineCell};
use crate::search::{distance_field, fastest_path, shortest_path};
use crate::seeds::{self, SeedProblem, ViaSeeds};
use crate::world::{Cell, World, MOVES};

use super::spec::{check_spec, PlanError, PlanSpec};

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
pub(super) struct Checked {
    pub(super) start: Cell,
    pub(super) goal: Cell,
    /// The path of least Eq. 2 time ([`fastest_path`]): the floor every budget is
    /// checked against, and what the `shortest` baseline returns.
    pub(super) fastest: Vec<Cell>,
    /// Its Eq. 2 time as driven, and whether the budget fits it (it does unless the
    /// spec asked for the fastest path as a fallback).
    pub(super) fastest_t_eta_s: f64,
    pub(super) budget_fits: bool,
    /// The path the GA's first population holds and [`best_of`] never falls below: the
    /// distance-shortest path when it fits the budget (the paper's floor, which the
    /// reproductions pin bit for bit), else the fastest path.
    pub(super) shortest: Vec<Cell>,
    /// The GA's size; `None` for the baseline.
    pub(super) size: Option<PlanSize>,
    /// On a world at a coarser planning resolution: how the start and goal join the
    /// planning grid, and the fastest path as the robot drives it (the floor).
    pub(super) anchors: Option<(Anchor, Anchor)>,
    pub(super) fastest_driven: Option<Vec<FineCell>>,
    /// The budget the planning grid plans with: t_exec less what driving the fastest
    /// path on the map's cells takes beyond its planning-grid ETA (the legs to and from
    /// the start's and goal's map cells), so that plans fit when driven. t_exec itself
    /// at the map's resolution.
    pub(super) planning_budget_s: f64,
    /// A replan's seed route on the planning grid ([`crate::remainder`]): `None`
    /// without one, `Some(Err(_))` when it could not be joined or the model plans no
    /// population (the baseline, a budget only the fastest path fits).
    pub(super) seed_route: Option<Result<Vec<Cell>, RemainderError>>,
}

impl Checked {
    /// The longest chromosome. The shortest path is in the first population and fits
    /// the budget, so the bound holds it (the max only guards rounding).
    pub(super) fn max_path_cells(&self, world: &World) -> usize {
        self.size
            .map_or(world.cell_count(), |s| s.path_cells)
            .max(self.shortest.len())
    }

    /// The seed route's path when it is planned from.
    pub(super) fn remainder(&self) -> Option<&[Cell]> {
        match &self.seed_route {
            Some(Ok(path)) => Some(path),
            _ => None,
        }
    }
}

/// Everything [`plan`] refuses before any work, and the shortest path: the one place
/// where "shortest" is decided, for the refusal, the GA's seed, the fallback and the
/// path attached to the reply.
pub(super) fn check(world: &World, spec: &PlanSpec) -> Result<Checked, PlanError> {
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
    let seed_route = (!spec.seed_route.is_empty()).then(|| match size {
        Some(size) if budget_fits => {
            let max_cells = size.path_cells.max(shortest.len());
            remainder::route_cells(world, &spec.seed_route, start, goal, max_cells)
        }
        _ => Err(RemainderError::NoPopulation),
    });
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
        seed_route,
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

pub(super) fn seeds_for(
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
