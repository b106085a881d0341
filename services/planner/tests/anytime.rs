//! The anytime portfolio (model `anytime`): the greedy planner's answer, then the GA
//! seeded with it; never less fit than the greedy answer alone, the same every time
//! when it ends at its generations, and the reply says which planner's path it is.

mod common;

use common::{check_geometry, run};
use roam_planner::best::PlanSource;
use roam_planner::plan::PlanSpec;
use roam_proto::planner::{PlanRequest, PlannerModel, ShortestPathUse};

#[test]
fn anytime_is_never_below_the_greedy_answer_and_says_which_it_returns() {
    let world = common::builtin_world();
    let mut sources = Vec::new();
    for (goal, budget) in [
        ([6.0, -7.0], 70.0),
        ([-2.0, 4.0], 60.0),
        ([-8.0, -8.0], 60.0),
    ] {
        let spec = PlanSpec::batch([-8.0, -8.0], goal, budget, PlannerModel::Anytime, 150, 4);
        let anytime = run(&world, &spec);
        check_geometry(&world, &spec, &anytime);
        assert!(anytime.within_budget && anytime.reaches_goal, "{goal:?}");
        let greedy = run(
            &world,
            &PlanSpec {
                model: PlannerModel::Greedy,
                ..spec.clone()
            },
        );
        assert!(
            anytime.fitness.total >= greedy.fitness.total,
            "{goal:?}: anytime {} below greedy {}",
            anytime.fitness.total,
            greedy.fitness.total
        );
        assert_eq!(greedy.source, PlanSource::Greedy);
        assert!(matches!(
            anytime.source,
            PlanSource::Greedy | PlanSource::Ga | PlanSource::ViaSeed(_) | PlanSource::Shortest
        ));
        // It ran the GA after the greedy answer.
        assert_eq!(anytime.generations, 150, "{goal:?}");
        // Ended at its generations, not a clock: the same answer every time.
        let again = run(&world, &spec);
        assert_eq!(again.path, anytime.path);
        assert_eq!(
            again.fitness.total.to_bits(),
            anytime.fitness.total.to_bits()
        );
        sources.push(anytime.source);
    }
    // The GA improves on the greedy answer on some trip (else the portfolio is the
    // greedy planner with a delay).
    assert!(sources.contains(&PlanSource::Ga), "{sources:?}");
}

#[test]
fn the_reply_names_the_planner_that_found_the_path() {
    let world = common::builtin_world();
    for (model, found_by) in [
        (PlannerModel::Greedy, &["greedy"][..]),
        (PlannerModel::Shortest, &["shortest"][..]),
        (
            PlannerModel::Anytime,
            &["greedy", "ga", "via_seed", "shortest"][..],
        ),
    ] {
        let request = PlanRequest {
            request_id: None,
            cancel_token: None,
            start: [-8.0, -8.0],
            goal: [6.0, -7.0],
            t_exec_s: 70.0,
            deadline_s: 5.0,
            model,
            params: roam_proto::planner::GaOverrides {
                max_generations: Some(50),
                ..Default::default()
            },
            seed: 1,
            map_version: None,
            shortest: ShortestPathUse::Omit,
            seed_route: Vec::new(),
        };
        let reply = roam_planner::answer::answer(&world, &request, 1).expect("a plan");
        let said = reply.found_by.expect("found_by");
        assert!(found_by.contains(&said.as_str()), "{model:?}: {said}");
        assert_eq!(reply.model, model);
    }
}
