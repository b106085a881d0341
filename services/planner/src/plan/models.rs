//! One function per planner: the fastest path (the `shortest` baseline), the greedy
//! peer, and paper 000's GA under a curiosity model. Each returns what it found as a
//! [`Found`], ranked with the plans it started from ([`crate::best`]), for
//! [`super::driven`] to drive.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use roam_proto::planner::StopReason;

use crate::best::{ranked, PlanSource, Scored};
use crate::curiosity::{Evaluator, Model};
use crate::ga::{self, GaOptions, Problem};
use crate::greedy::{self, GreedyProblem};
use crate::params::GaParams;
use crate::search::distance_field;
use crate::world::{Cell, World};

use super::check::{seeds_for, Checked};
use super::spec::PlanSpec;

/// What one planner found, before it is driven.
#[derive(Debug)]
pub(super) struct Found {
    /// Its plan and the plans it started from, fittest first.
    pub ranked: Vec<Scored>,
    /// The model the candidates are scored with when driven.
    pub scoring: Model,
    /// GA generations, or the greedy planner's rounds.
    pub generations: u32,
    pub evaluations: u64,
    pub evaluated_genes: u64,
    pub stop_reason: StopReason,
    /// The via-point seeds the GA's first population held.
    pub via_seeds: usize,
}

/// The fastest path. Its fitness terms are scored with Model I, the paper's best, so
/// that they compare with the curious plans.
pub(super) fn fastest(world: &World, params: &GaParams, checked: &Checked) -> Found {
    let budget = checked.planning_budget_s;
    let mut evaluator = Evaluator::new(world, params, Model::Novelty, checked.goal, budget);
    let evaluation = evaluator.evaluate(&checked.fastest);
    Found {
        ranked: vec![Scored {
            path: checked.fastest.clone(),
            evaluation,
            source: PlanSource::Shortest,
        }],
        scoring: Model::Novelty,
        generations: 0,
        evaluations: 1,
        evaluated_genes: checked.fastest.len() as u64,
        stop_reason: StopReason::Complete,
        via_seeds: 0,
    }
}

/// The greedy peer ([`crate::greedy`]), from the shortest path that fits.
pub(super) fn greedy(
    world: &World,
    params: &GaParams,
    checked: &Checked,
    deadline: Instant,
    cancel: &AtomicBool,
    mut progress: impl FnMut(u32, f64),
) -> Found {
    let (goal, budget) = (checked.goal, checked.planning_budget_s);
    let field = distance_field(world, goal);
    let problem = GreedyProblem {
        world,
        params,
        start: checked.start,
        goal,
        t_exec: budget,
        floor: &checked.shortest,
        goal_field: &field,
    };
    let result = greedy::run(&problem, deadline, cancel);
    progress(result.rounds, result.evaluation.fitness.total);
    let stop_reason = match (result.interrupted, cancel.load(Ordering::Relaxed)) {
        (false, _) => StopReason::Complete,
        (true, true) => StopReason::Cancelled,
        (true, false) => StopReason::Deadline,
    };
    let found = Scored {
        path: result.path,
        evaluation: result.evaluation,
        source: PlanSource::Greedy,
    };
    let mut evaluator = Evaluator::new(world, params, Model::Novelty, goal, budget);
    Found {
        ranked: ranked(
            &mut evaluator,
            found,
            &checked.shortest,
            checked.remainder(),
            &[],
        ),
        scoring: Model::Novelty,
        generations: result.rounds,
        evaluations: result.evaluations,
        evaluated_genes: result.evaluated_genes,
        stop_reason,
        via_seeds: 0,
    }
}

/// Paper 000's GA under `model`, its first population seeded with the shortest path and
/// the via-point seeds ([`crate::seeds`]) unless the spec asks for the paper's random
/// walks only.
pub(super) fn ga(
    world: &World,
    spec: &PlanSpec,
    checked: &Checked,
    model: Model,
    deadline: Instant,
    cancel: &AtomicBool,
    progress: impl FnMut(u32, f64),
) -> Found {
    ga_from(
        world, spec, checked, model, None, deadline, cancel, progress,
    )
}

/// The anytime portfolio: the greedy planner's route at once, then the GA under Model I
/// with that route in its first population until the deadline; both ranked together
/// (the greedy route first on a tie, so a GA that only kept it reports `greedy`).
pub(super) fn anytime(
    world: &World,
    spec: &PlanSpec,
    checked: &Checked,
    deadline: Instant,
    cancel: &AtomicBool,
    mut progress: impl FnMut(u32, f64),
) -> Found {
    let quick = greedy(
        world,
        &spec.params,
        checked,
        deadline,
        cancel,
        &mut progress,
    );
    let route = quick.ranked.iter().find(|s| s.source == PlanSource::Greedy);
    let seed = route.map(|s| s.path.clone());
    let mut found = ga_from(
        world,
        spec,
        checked,
        Model::Novelty,
        seed,
        deadline,
        cancel,
        progress,
    );
    let mut all = quick.ranked;
    all.extend(found.ranked);
    // Stable: on a tie the greedy route (listed first) stays ahead of the GA's copy.
    all.sort_by(|a, b| {
        b.evaluation
            .fitness
            .total
            .total_cmp(&a.evaluation.fitness.total)
    });
    found.ranked = all;
    found.evaluations += quick.evaluations;
    found.evaluated_genes += quick.evaluated_genes;
    found
}

/// [`ga`], with `extra_seed` (a route found otherwise) in the first population after
/// the shortest path.
#[allow(clippy::too_many_arguments)]
fn ga_from(
    world: &World,
    spec: &PlanSpec,
    checked: &Checked,
    model: Model,
    extra_seed: Option<Vec<Cell>>,
    deadline: Instant,
    cancel: &AtomicBool,
    progress: impl FnMut(u32, f64),
) -> Found {
    let params = &spec.params;
    let (goal, budget) = (checked.goal, checked.planning_budget_s);
    let field = distance_field(world, goal);
    let stop = || cancel.load(Ordering::Relaxed) || Instant::now() >= deadline;
    // Paper 000 to the letter (GaParams::random_walks_only): random walks only, nothing
    // seeded and nothing to fall back on.
    let strict = params.random_walks_only;
    let seeds = if strict {
        Vec::new()
    } else {
        seeds_for(world, spec, checked, &field, &stop).paths
    };
    let via_seeds = seeds.len();
    // The shortest path first, then the remainder of the robot's route (a replan's warm
    // start, crate::remainder), the extra route, the via-point seeds (see crate::ga).
    let mut seed_paths = Vec::with_capacity(3 + via_seeds);
    if !strict {
        seed_paths.push(checked.shortest.clone());
    }
    let remainder = checked.remainder().filter(|_| !strict);
    seed_paths.extend(remainder.map(<[Cell]>::to_vec));
    let extra = usize::from(remainder.is_some()) + usize::from(extra_seed.is_some());
    seed_paths.extend(extra_seed);
    seed_paths.extend(seeds);
    let problem = Problem {
        world,
        params,
        model,
        start: checked.start,
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
        // The paper's walks may be as long as the map has cells (§II.A.1); roam bounds
        // chromosomes by the budget (crate::limits). Only the reproduction sets
        // `random_walks_only` (no request can), so the size promise to requesters holds.
        max_path_cells: if strict {
            checked.max_path_cells(world).max(world.traversable_count())
        } else {
            checked.max_path_cells(world)
        },
        threads: spec.threads,
    };
    let result = ga::run(&problem, &options, cancel, progress);
    let found = Scored {
        path: result.best,
        evaluation: result.evaluation,
        source: PlanSource::Ga,
    };
    let ranked = if strict {
        vec![found]
    } else {
        let mut evaluator = Evaluator::new(world, params, model, goal, budget);
        // The via-point seeds after the shortest path, the remainder and the extra
        // route (which its planner ranks itself).
        ranked(
            &mut evaluator,
            found,
            &checked.shortest,
            remainder,
            &seed_paths[1 + extra..],
        )
    };
    Found {
        ranked,
        scoring: model,
        generations: result.generations,
        evaluations: result.evaluations,
        evaluated_genes: result.evaluated_genes,
        stop_reason: result.stop_reason,
        via_seeds,
    }
}
