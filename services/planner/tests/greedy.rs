//! The greedy peer (model `greedy`, issue 16): legal, within the budget, at the goal,
//! the same every time, and more informative than the shortest path, round trips
//! included.

mod common;

use common::{check_geometry, run};
use roam_planner::plan::PlanSpec;
use roam_proto::planner::{PlannerModel, StopReason};

#[test]
fn greedy_plans_are_legal_repeatable_and_more_informative_than_the_shortest_path() {
    let world = common::builtin_world();
    for (goal, budget) in [
        ([6.0, -7.0], 70.0),
        ([-2.0, 4.0], 60.0),
        ([-8.0, -8.0], 60.0),
    ] {
        let spec = PlanSpec::batch([-8.0, -8.0], goal, budget, PlannerModel::Greedy, 1, 0);
        let greedy = run(&world, &spec);
        check_geometry(&world, &spec, &greedy);
        assert!(greedy.within_budget && greedy.reaches_goal, "{goal:?}");
        assert_eq!(greedy.stop_reason, StopReason::Complete);
        let again = run(&world, &spec);
        assert_eq!(again.path, greedy.path, "no randomness");
        let shortest = run(
            &world,
            &PlanSpec {
                model: PlannerModel::Shortest,
                ..spec.clone()
            },
        );
        assert!(
            greedy.metrics.distinct_information > 1.5 * shortest.metrics.distinct_information,
            "{goal:?}: {} vs {}",
            greedy.metrics.distinct_information,
            shortest.metrics.distinct_information
        );
        // It spends the budget, as F5 (Eq. 7) asks.
        assert!(
            greedy.t_eta_s > 0.7 * budget,
            "{goal:?}: {} s",
            greedy.t_eta_s
        );
    }
}
