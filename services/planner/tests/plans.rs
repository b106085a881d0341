//! Properties of every plan: geometry, budgets, determinism, the paper's claims in
//! miniature, and the refusals.

mod common;

use std::sync::atomic::AtomicBool;

use common::{check_geometry, run, small_spec};
use proptest::prelude::*;
use roam_planner::best::PlanSource;
use roam_planner::params::ParamError;
use roam_planner::plan::{plan, PlanError, PlanSpec, START_SNAP_M};
use roam_planner::world::World;
use roam_proto::planner::{PlannerModel, ShortestPathUse, StopReason};

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn every_plan_is_a_legal_path_from_s(
        seed in any::<u64>(),
        model in prop_oneof![Just(PlannerModel::Model0), Just(PlannerModel::Model1), Just(PlannerModel::Model2), Just(PlannerModel::Shortest)],
        sx in -9.0..9.0f64, sy in -9.0..9.0f64, gx in -9.0..9.0f64, gy in -9.0..9.0f64,
        slack in 1.0..3.0f64,
    ) {
        let world = common::builtin_world();
        let mut s = small_spec(model, [sx, sy], [gx, gy], 1.0, seed, 30);
        // Find the shortest ETA by asking with a huge budget first.
        s.t_exec_s = 86_400.0;
        // A blocked start or goal is rejected, not passed: proptest draws another case,
        // so 24 cases plan for real (and it fails after too many rejections).
        let needed = match plan(&world, &PlanSpec { model: PlannerModel::Shortest, ..s.clone() }, &AtomicBool::new(false), |_, _| {}) {
            Ok(outcome) => outcome.t_eta_s,
            Err(PlanError::Blocked { .. }) | Err(PlanError::NoPath) => {
                return Err(TestCaseError::reject("start or goal blocked"))
            }
            Err(e) => panic!("{e}"),
        };
        s.t_exec_s = (needed * slack).max(1.0);
        let outcome = run(&world, &s);
        check_geometry(&world, &s, &outcome);
    }
}

#[test]
fn the_same_seed_gives_the_same_path_bit_for_bit() {
    let world = common::builtin_world();
    for model in [
        PlannerModel::Model0,
        PlannerModel::Model1,
        PlannerModel::Model2,
    ] {
        let s = small_spec(model, [-8.0, -8.0], [6.0, -7.0], 80.0, 42, 100);
        let a = run(&world, &s);
        let b = run(&world, &s);
        assert_eq!(a.path, b.path, "{model:?}");
        assert_eq!(a.fitness.total.to_bits(), b.fitness.total.to_bits());
        let single = run(
            &world,
            &PlanSpec {
                threads: 1,
                ..s.clone()
            },
        );
        assert_eq!(
            single.path, a.path,
            "the thread count does not change the plan ({model:?})"
        );
        let c = run(&world, &PlanSpec { seed: 43, ..s });
        assert_ne!(
            a.path, c.path,
            "another seed explores differently ({model:?})"
        );
    }
}

#[test]
fn curious_plans_use_the_budget_and_gather_more_than_the_shortest_path() {
    let world = common::builtin_world();
    let shortest = run(
        &world,
        &small_spec(
            PlannerModel::Shortest,
            [-8.0, -8.0],
            [-2.0, 4.0],
            600.0,
            1,
            1,
        ),
    );
    let budget = shortest.t_eta_s * 2.0;
    for model in [
        PlannerModel::Model0,
        PlannerModel::Model1,
        PlannerModel::Model2,
    ] {
        let s = small_spec(model, [-8.0, -8.0], [-2.0, 4.0], budget, 7, 400);
        let outcome = run(&world, &s);
        check_geometry(&world, &s, &outcome);
        // On time at the goal is forced by the shortest-path seed (issue 18) and checked
        // by `check_geometry`; using the budget is not: the shortest path drives half
        // of it, and only F5 (Eq. 7) pushes the GA further.
        assert!(
            outcome.t_eta_s >= 0.8 * budget,
            "{model:?}: eta {} of {budget}",
            outcome.t_eta_s
        );
        assert!(
            outcome.metrics.distinct_information > shortest.metrics.distinct_information,
            "{model:?} saw {} vs shortest {}",
            outcome.metrics.distinct_information,
            shortest.metrics.distinct_information
        );
    }
}

/// The shortest path comes with a plan only when asked, exactly as the baseline finds
/// and measures it; with the fallback, a budget it does not fit is answered with it.
#[test]
fn the_shortest_path_is_attached_when_asked_and_is_the_fallback() {
    let world = common::builtin_world();
    let (from, to) = ([-8.0, -8.0], [6.0, -7.0]);
    let baseline = run(
        &world,
        &small_spec(PlannerModel::Shortest, from, to, 100.0, 1, 5),
    );
    let curious = small_spec(PlannerModel::Model1, from, to, 100.0, 1, 5);
    assert!(run(&world, &curious).shortest.is_none(), "not asked for");
    let attached = run(
        &world,
        &PlanSpec {
            shortest: ShortestPathUse::Attach,
            ..curious.clone()
        },
    );
    assert_eq!(attached.model, PlannerModel::Model1);
    let shortest = attached.shortest.expect("attached");
    assert_eq!(shortest.path, baseline.path);
    assert_eq!(shortest.t_eta_s.to_bits(), baseline.t_eta_s.to_bits());
    assert_eq!(
        shortest.metrics.distinct_information.to_bits(),
        baseline.metrics.distinct_information.to_bits()
    );

    let short = PlanSpec {
        t_exec_s: 0.5 * baseline.t_eta_s,
        ..curious
    };
    for refused in [ShortestPathUse::Omit, ShortestPathUse::Attach] {
        let outcome = plan(
            &world,
            &PlanSpec {
                shortest: refused,
                ..short.clone()
            },
            &AtomicBool::new(false),
            |_, _| {},
        );
        assert!(
            matches!(outcome, Err(PlanError::BudgetTooShort { .. })),
            "{refused:?}: {outcome:?}"
        );
    }
    let fallback = run(
        &world,
        &PlanSpec {
            shortest: ShortestPathUse::Fallback,
            ..short
        },
    );
    assert_eq!(fallback.model, PlannerModel::Shortest);
    assert_eq!(fallback.path, baseline.path);
    assert!(fallback.reaches_goal && !fallback.within_budget);
    assert_eq!(fallback.stop_reason, StopReason::Complete);
    assert_eq!(fallback.generations, 0);
    assert_eq!(fallback.shortest.expect("attached").path, baseline.path);
}

#[test]
fn refusals_say_what_to_change() {
    let world = common::builtin_world();
    let off = plan(
        &world,
        &small_spec(PlannerModel::Model1, [50.0, 0.0], [0.0, 0.0], 100.0, 1, 5),
        &AtomicBool::new(false),
        |_, _| {},
    );
    assert!(
        matches!(off, Err(PlanError::OffMap { which: "start", .. })),
        "{off:?}"
    );
    let wall = plan(
        &world,
        &small_spec(PlannerModel::Model1, [-8.0, -8.0], [-9.9, 0.0], 100.0, 1, 5),
        &AtomicBool::new(false),
        |_, _| {},
    );
    assert!(
        matches!(wall, Err(PlanError::Blocked { which: "goal", .. })),
        "{wall:?}"
    );
    let short = plan(
        &world,
        &small_spec(PlannerModel::Model1, [-8.0, -8.0], [6.0, -7.0], 5.0, 1, 5),
        &AtomicBool::new(false),
        |_, _| {},
    );
    match short {
        Err(PlanError::BudgetTooShort {
            given_s,
            needed_s,
            short_by_s,
        }) => {
            assert_eq!(given_s, 5.0);
            assert!((needed_s - given_s - short_by_s).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    let deadline = plan(
        &world,
        &PlanSpec {
            deadline_s: 0.0,
            ..small_spec(PlannerModel::Model1, [-8.0, -8.0], [6.0, -7.0], 100.0, 1, 5)
        },
        &AtomicBool::new(false),
        |_, _| {},
    );
    assert!(matches!(
        deadline,
        Err(PlanError::Param(ParamError {
            name: "deadline_s",
            ..
        }))
    ));
}

#[test]
fn a_walled_in_goal_has_no_path() {
    let mut world = common::open_world(30, 30);
    // Rebuild with a ring of walls around the goal cell (15, 15).
    let meta = world.meta;
    let mut occupancy = roam_world::grid::Grid::filled(meta, 0i8);
    for (x, y) in [
        (13, 13),
        (14, 13),
        (15, 13),
        (16, 13),
        (17, 13),
        (13, 17),
        (14, 17),
        (15, 17),
        (16, 17),
        (17, 17),
        (13, 14),
        (13, 15),
        (13, 16),
        (17, 14),
        (17, 15),
        (17, 16),
    ] {
        occupancy.cells[y * 30 + x] = 100;
    }
    let information = roam_world::grid::Grid {
        meta,
        cells: world.information.clone(),
    };
    world = World::new(&occupancy, &information, 0.25).expect("world");
    let outcome = plan(
        &world,
        &small_spec(PlannerModel::Model1, [0.5, 0.5], [3.1, 3.1], 100.0, 1, 5),
        &AtomicBool::new(false),
        |_, _| {},
    );
    assert_eq!(outcome.expect_err("must be refused"), PlanError::NoPath);
}

/// `GaParams::random_walks_only` (paper 000 §II.A.1 to the letter) seeds nothing and
/// falls back on nothing: the plan is the GA's own, and still a legal path from S.
/// Without the shortest path the first population's walks reach G (12 m away) only
/// after hundreds of random cells, far over a 60 s budget, and W_3 > W_2 (Table I)
/// keeps the late arrival over any on-time walk that stops short: after 50
/// generations the plan is at G but late. With the shortest path seeded (roam's
/// default) it is on time, so this fails if anything seeds it.
#[test]
fn the_papers_own_initialization_seeds_nothing() {
    let world = common::builtin_world();
    for model in [PlannerModel::Model0, PlannerModel::Model1] {
        let mut s = small_spec(model, [-8.0, -8.0], [-2.0, 4.0], 60.0, 3, 50);
        let roam = run(&world, &s);
        assert!(roam.within_budget && roam.reaches_goal, "{model:?}");
        s.params = s.params.with_random_walks_only();
        let outcome = run(&world, &s);
        check_geometry(&world, &s, &outcome);
        assert_eq!(outcome.via_seeds, 0, "{model:?}");
        assert_eq!(outcome.source, PlanSource::Ga, "{model:?}");
        assert!(
            outcome.reaches_goal && !outcome.within_budget,
            "{model:?}: {} s of 60 s",
            outcome.t_eta_s
        );
    }
}

/// Issue 16: the budget floor is the path of least Eq. 2 time, turns counted. From the
/// start to Goal 2 of the built-in world the distance-shortest path zigzags (34.7 s)
/// where a 32.4 s path exists; a budget between the two is admitted, every model plans
/// within it, the `shortest` baseline returns the fastest path, and a budget below the
/// fastest path is refused naming its time.
#[test]
fn the_fastest_path_floor_admits_a_budget_the_distance_shortest_path_would_refuse() {
    use roam_planner::eta::path_eta;
    use roam_planner::search::{fastest_path, shortest_path};
    let world = common::builtin_world();
    let params = roam_planner::params::GaParams::default();
    let (start, goal) = ([-8.0, -8.0], [6.0, -7.0]);
    let (s, g) = (
        world.cell_at(start[0], start[1]).expect("start"),
        world.cell_at(goal[0], goal[1]).expect("goal"),
    );
    let by_distance = path_eta(&world, &params, &shortest_path(&world, s, g).expect("path"));
    let fastest = path_eta(
        &world,
        &params,
        &fastest_path(&world, &params, s, g).expect("path"),
    );
    assert!(fastest < by_distance - 1.0, "{fastest} vs {by_distance}");
    let budget = (fastest + by_distance) / 2.0;
    for model in [
        PlannerModel::Shortest,
        PlannerModel::Model0,
        PlannerModel::Model1,
        PlannerModel::Model2,
    ] {
        let outcome = run(
            &world,
            &PlanSpec {
                shortest: ShortestPathUse::Attach,
                ..small_spec(model, start, goal, budget, 3, 20)
            },
        );
        assert!(outcome.within_budget && outcome.reaches_goal, "{model:?}");
        assert!(outcome.t_eta_s <= budget);
        if model == PlannerModel::Shortest {
            assert_eq!(outcome.t_eta_s.to_bits(), fastest.to_bits());
        }
        // The path attached as `shortest` is the floor it was checked against.
        let attached = outcome.shortest.expect("attached");
        assert_eq!(attached.t_eta_s.to_bits(), fastest.to_bits());
        assert_eq!(attached.cells.len(), attached.points.len());
    }
    let refused = plan(
        &world,
        &small_spec(PlannerModel::Model1, start, goal, fastest - 0.1, 3, 20),
        &AtomicBool::new(false),
        |_, _| {},
    );
    match refused {
        Err(e @ PlanError::BudgetTooShort { needed_s, .. }) => {
            assert_eq!(needed_s.to_bits(), fastest.to_bits());
            assert!(e.to_string().contains(&format!("{fastest:.1} s")), "{e}");
        }
        other => panic!("{other:?}"),
    }
}

/// A deadline bounds the work. Model I with 100,000 generations and a
/// 2 s deadline on the built-in world (an 80 s budget: paths of at most 201 cells) would
/// cost 200 × 100,000 × 201 = 4.02e9, over `max_plan_cost`; the GA stops at its
/// deadline, so only the generations that can start before it count, and the request is
/// admitted and planned: cut at the deadline, its best path so far. One whose deadline
/// lets the whole cost run is still refused, the limit named.
#[test]
fn a_deadline_bounds_the_work_a_plan_is_sized_by() {
    let world = common::builtin_world();
    let mut curious = PlanSpec::batch(
        [-8.0, -8.0],
        [6.0, -7.0],
        80.0,
        PlannerModel::Model1,
        100_000,
        3,
    );
    curious.threads = 4;
    curious.deadline_s = 2.0;
    let work = roam_planner::plan::work(&world, &curious).expect("admitted: no LimitError");
    // 2 s × 4 threads × 2.5e8 cells per thread-second / (200 × 201), and one more.
    assert_eq!(work.generations, 49_752);
    assert_eq!(work.cost, 200 * 49_752 * 201);

    // The batch deadline (600 s) lets all 100,000 generations run: over the cap.
    let batch = PlanSpec {
        deadline_s: roam_planner::plan::MAX_DEADLINE_S,
        ..curious.clone()
    };
    match roam_planner::plan::work(&world, &batch) {
        Err(PlanError::Limit(limit)) => {
            assert_eq!(limit.name(), "max_plan_cost");
            assert_eq!(limit.max_actual(), (4_000_000_000, 200 * 100_000 * 201));
        }
        other => panic!("expected max_plan_cost, got {other:?}"),
    }
    // Population 2000 with a 10 s deadline: 24,876 generations fit, still 1e10 cells.
    let wide = PlanSpec {
        deadline_s: 10.0,
        params: roam_planner::params::GaParams {
            population: 2000,
            ..curious.params.clone()
        },
        ..curious.clone()
    };
    match plan(&world, &wide, &AtomicBool::new(false), |_, _| {}) {
        Err(PlanError::Limit(limit)) => {
            assert_eq!(limit.name(), "max_plan_cost");
            assert_eq!(limit.max_actual().1, 2000 * 24_876 * 201);
            let reply = PlanError::Limit(limit).to_reply();
            assert_eq!(
                reply.limit.map(|l| l.name),
                Some("max_plan_cost".to_owned())
            );
        }
        other => panic!("expected max_plan_cost, got {other:?}"),
    }

    // Planned, not refused, and cut at the deadline (here 1 s, less work still).
    let quick = PlanSpec {
        deadline_s: 1.0,
        ..curious
    };
    let started = std::time::Instant::now();
    let outcome = run(&world, &quick);
    assert!(
        started.elapsed().as_secs_f64() < 3.0,
        "{:?}",
        started.elapsed()
    );
    assert_eq!(outcome.stop_reason, StopReason::Deadline);
    assert!(
        (1..100_000).contains(&outcome.generations),
        "{}",
        outcome.generations
    );
    assert!(outcome.reaches_goal && outcome.within_budget);
}

/// A start inside an obstacle's edge (a robot pushed aside, or beside what the fleet
/// saw) plans from the nearest free cell within `START_SNAP_M`; one deeper inside is
/// refused, naming the start, and a goal is never moved.
#[test]
fn a_start_at_an_obstacles_edge_moves_to_the_nearest_free_cell() {
    let world = common::open_world(30, 30);
    let meta = world.meta;
    let mut occupancy = roam_world::grid::Grid::filled(meta, 0i8);
    for y in 10..=20 {
        for x in 10..=20 {
            occupancy.cells[y * 30 + x] = 100;
        }
    }
    let information = roam_world::grid::Grid {
        meta,
        cells: world.information.clone(),
    };
    let world = World::new(&occupancy, &information, 0.25).expect("world");
    let centre = |x: usize, y: usize| roam_world::grid::cell_center(&meta, x, y);
    let (ex, ey) = centre(10, 15);
    let edge = run(
        &world,
        &small_spec(PlannerModel::Shortest, [ex, ey], [0.5, 0.5], 100.0, 1, 5),
    );
    let first = edge.points[0];
    assert_eq!(first, {
        let (x, y) = centre(9, 15);
        [x, y]
    });
    assert!(((first[0] - ex).powi(2) + (first[1] - ey).powi(2)).sqrt() <= START_SNAP_M);
    let (cx, cy) = centre(15, 15);
    let deep = plan(
        &world,
        &small_spec(PlannerModel::Shortest, [cx, cy], [0.5, 0.5], 100.0, 1, 5),
        &AtomicBool::new(false),
        |_, _| {},
    );
    assert!(
        matches!(deep, Err(PlanError::Blocked { which: "start", .. })),
        "{deep:?}"
    );
    let goal = plan(
        &world,
        &small_spec(PlannerModel::Shortest, [0.5, 0.5], [ex, ey], 100.0, 1, 5),
        &AtomicBool::new(false),
        |_, _| {},
    );
    assert!(
        matches!(goal, Err(PlanError::Blocked { which: "goal", .. })),
        "{goal:?}"
    );
}
