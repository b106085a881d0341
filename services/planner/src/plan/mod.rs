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

mod check;
mod driven;
mod models;
mod spec;

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use roam_proto::planner::{PlannerModel, ShortestPathUse};

use crate::curiosity::Model;
use crate::world::World;

pub use check::{via_seeds, work, Work, START_SNAP_M};
pub use driven::MAX_DRIVEN_CANDIDATES;
pub use spec::{
    check_spec, PlanError, PlanOutcome, PlanSpec, ShortestOutcome, MAX_DEADLINE_S, MAX_T_EXEC_S,
};

/// Plans on `world`. `progress` gets each generation's best fitness; `cancel` stops
/// the GA early (the best path so far is returned).
pub fn plan(
    world: &World,
    spec: &PlanSpec,
    cancel: &AtomicBool,
    progress: impl FnMut(u32, f64),
) -> Result<PlanOutcome, PlanError> {
    let started = Instant::now();
    let checked = check::check(world, spec)?;
    let params = &spec.params;
    let deadline = started + Duration::from_secs_f64(spec.deadline_s);
    // A budget the fastest path does not fit (asked for as a fallback): the fastest
    // path answers, as the baseline would.
    let model = if checked.budget_fits {
        spec.model
    } else {
        PlannerModel::Shortest
    };
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
    let found = match Model::of(model) {
        None => models::fastest(world, params, &checked),
        Some(_) if model == PlannerModel::Greedy => {
            models::greedy(world, params, &checked, deadline, cancel, progress)
        }
        Some(_) if model == PlannerModel::Anytime => {
            models::anytime(world, spec, &checked, deadline, cancel, progress)
        }
        Some(curiosity) => models::ga(world, spec, &checked, curiosity, deadline, cancel, progress),
    };
    let driven = driven::drive(world, spec, &checked, found.scoring, found.ranked);
    let shortest = (spec.shortest != ShortestPathUse::Omit)
        .then(|| driven::fastest_as_driven(world, params, &checked));
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
        generations: found.generations,
        evaluations: found.evaluations,
        evaluated_genes: found.evaluated_genes,
        planning: started.elapsed(),
        stop_reason: found.stop_reason,
        source: driven.chosen.source,
        via_seeds: found.via_seeds,
        seed_route_used: checked.seed_route.as_ref().map(Result::is_ok),
        shortest,
    })
}
