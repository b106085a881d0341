//! A replan's warm start (`PlanRequest::seed_route`, `roam_planner::remainder`): the
//! route the robot drives is planned from, the answer is never less fit than driving
//! on, a route that cannot be joined is a hint not taken (never a refusal), and a route
//! over the limit is refused naming it.

mod common;

use std::sync::atomic::AtomicBool;

use common::{builtin_world, check_geometry};
use roam_planner::curiosity::{Evaluator, Model};
use roam_planner::eta::path_eta;
use roam_planner::plan::{plan, PlanError, PlanOutcome, PlanSpec};
use roam_planner::remainder::{route_cells, MAX_SEED_ROUTE_POINTS};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;

const GOAL: [f64; 2] = [6.0, -7.0];

fn spec(start: [f64; 2], t_exec_s: f64, generations: u32) -> PlanSpec {
    let mut spec = PlanSpec::batch(start, GOAL, t_exec_s, PlannerModel::Model1, generations, 7);
    spec.params.population = 60;
    spec.threads = 1;
    spec
}

fn run(world: &World, spec: &PlanSpec) -> Result<PlanOutcome, PlanError> {
    plan(world, spec, &AtomicBool::new(false), |_, _| {})
}

/// The first plan of a window and the replan a third of the way along it: from the
/// point the robot reached, to the same goal, with the time its route has left.
fn first_and_replan(world: &World) -> (PlanOutcome, PlanSpec) {
    let first = run(world, &spec([-8.0, -8.0], 80.0, 300)).expect("first plan");
    let from = first.points.len() / 3;
    let left = &first.points[from..];
    let (cells, params) = (&first.path, &spec([0.0; 2], 1.0, 1).params);
    let eta_left = path_eta(world, params, &cells[cells.len() / 3..]);
    let mut replan = spec(left[0], eta_left.max(10.0) * 1.2, 3);
    replan.seed_route = left.to_vec();
    (first, replan)
}

#[test]
fn a_replan_starts_from_the_route_left_and_is_never_less_fit_than_driving_on() {
    let world = builtin_world();
    let (_, replan) = first_and_replan(&world);
    let outcome = run(&world, &replan).expect("replan");
    check_geometry(&world, &replan, &outcome);
    assert_eq!(outcome.seed_route_used, Some(true));

    // The route left, on the planning grid, scored as the planner scores its plans.
    let start = world
        .cell_at(replan.start[0], replan.start[1])
        .expect("start");
    let goal = world.cell_at(GOAL[0], GOAL[1]).expect("goal");
    let left = route_cells(&world, &replan.seed_route, start, goal, usize::MAX).expect("joined");
    let mut evaluator = Evaluator::new(
        &world,
        &replan.params,
        Model::Novelty,
        goal,
        replan.t_exec_s,
    );
    let driving_on = evaluator.evaluate(&left).fitness.total;
    assert!(
        outcome.fitness.total >= driving_on,
        "the replan ({}) is less fit than the route it was seeded with ({driving_on})",
        outcome.fitness.total
    );

    // Without the seed route, the same three generations from scratch.
    let scratch = run(
        &world,
        &PlanSpec {
            seed_route: Vec::new(),
            ..replan.clone()
        },
    )
    .expect("from scratch");
    assert_eq!(scratch.seed_route_used, None);

    // Bit for bit again.
    let again = run(&world, &replan).expect("again");
    assert_eq!(again.path, outcome.path);
    assert_eq!(
        again.fitness.total.to_bits(),
        outcome.fitness.total.to_bits()
    );
}

#[test]
fn a_route_that_cannot_be_joined_is_not_used_and_the_request_is_answered() {
    let world = builtin_world();
    let (_, mut replan) = first_and_replan(&world);
    // A jump across the map: no one or two moves join it.
    replan.seed_route = vec![replan.start, [8.0, 8.0], GOAL];
    let outcome = run(&world, &replan).expect("answered");
    assert_eq!(outcome.seed_route_used, Some(false));
    // The baseline has no population to seed.
    replan.model = PlannerModel::Shortest;
    let (_, route) = first_and_replan(&world);
    replan.seed_route = route.seed_route;
    assert_eq!(
        run(&world, &replan).expect("answered").seed_route_used,
        Some(false)
    );
}

#[test]
fn a_seed_route_over_the_limit_or_not_finite_is_refused_naming_it() {
    let world = builtin_world();
    let (_, mut replan) = first_and_replan(&world);
    replan.seed_route = vec![replan.start; MAX_SEED_ROUTE_POINTS + 1];
    let err = run(&world, &replan).expect_err("over the limit");
    assert_eq!(err.kind(), "limit");
    assert_eq!(
        err.to_reply().limit.expect("limit").name,
        "max_seed_route_points"
    );
    replan.seed_route = vec![replan.start, [f64::NAN, 0.0]];
    let err = run(&world, &replan).expect_err("not finite");
    assert!(err.to_string().contains("seed_route"), "{err}");
}
