//! The fleet's batch on a short shift in the built-in warehouse (two robots, two
//! windows each, ten sim minutes): the executive's own window machine per robot, the
//! planner's and the mapper's own code. Common random numbers hold (the same objects
//! land and leave whatever the variant), the report does not depend on the number of
//! threads, no task is late, and the curious fleet drives more information than the
//! one that only does its tasks; two robots offered the same news take different
//! cells.

use std::collections::BTreeSet;
use std::sync::OnceLock;

use roam_experiments::reproduce::fleet::mapper::FleetMapper;
use roam_experiments::reproduce::fleet::FleetWorld;
use roam_experiments::reproduce::fleet::{self, FleetOptions, FleetReport, FleetVariant};
use roam_mapper::news::DEFAULT_NEWS_PRIOR;
use roam_mission::calibration::TimeModel;
use roam_mission::shift::WAREHOUSE_SCENARIO;
use roam_planner::coupling::{Coupling, DEFAULT_NEWS_FLOOR};
use roam_proto::planner::{Plan, PlanRequest, PlannerModel};

const SHIFT: &str = "
length_s: 600.0
robots:
  - robot: r1
    tasks:
      - { name: dock-1, place: dock-3, start_s: 150.0, duration_s: 30.0 }
      - { name: pick-1, place: aisle-8-south, start_s: 330.0, duration_s: 40.0 }
  - robot: r2
    tasks:
      - { name: pick-1, place: aisle-3-north, start_s: 160.0, duration_s: 30.0 }
      - { name: pack-1, place: pack-1, start_s: 360.0, duration_s: 40.0 }
";

/// The warehouse with the short shift, built once for the file's tests.
fn world() -> &'static FleetWorld {
    static WORLD: OnceLock<FleetWorld> = OnceLock::new();
    WORLD.get_or_init(|| {
        FleetWorld::new(WAREHOUSE_SCENARIO, SHIFT).expect("the warehouse and its shift")
    })
}

fn run(world: &FleetWorld, variants: Vec<FleetVariant>, jobs: usize) -> FleetReport {
    let options = FleetOptions {
        days: 1,
        seed: 3,
        variants,
        jobs,
        ..FleetOptions::default()
    };
    fleet::run_on(world, &options, &roam_experiments::progress::silent).expect("the fleet's batch")
}

#[test]
fn a_short_shift_is_on_time_repeatable_and_curious() {
    let world = world();
    let both = vec![FleetVariant::TasksOnly, FleetVariant::News];
    let report = run(world, both, 2);
    let alone = run(world, vec![FleetVariant::News], 1);

    let [tasks_only, news] = &report.weeks[..] else {
        panic!("two weeks: {:?}", report.weeks.len());
    };
    // Common random numbers: the world's changes do not depend on the variant.
    let schedule = |w: &fleet::measure::WeekRecord| -> Vec<(u64, f64)> {
        w.events.iter().map(|e| (e.object, e.at_s)).collect()
    };
    assert!(!news.events.is_empty(), "objects landed in ten minutes");
    assert_eq!(schedule(tasks_only), schedule(news));
    // The threads change nothing but the wall clock.
    assert_eq!(alone.weeks[0].windows, news.windows);
    assert_eq!(alone.weeks[0].events, news.events);
    assert_eq!(alone.weeks[0].maps, news.maps);

    for s in &report.variants {
        assert_eq!(s.windows, 4, "{s:?}");
        assert_eq!(s.late, 0, "{s:?}");
    }
    let (t, n) = (&report.variants[0], &report.variants[1]);
    assert_eq!((t.variant, n.variant), ("tasks_only", "news"));
    assert_eq!(t.curious_plans, 0);
    assert!(n.curious_plans > 0, "{n:?}");
    // The static map knows no change: its score is the world's alone, the same for
    // every variant on common random numbers, and above zero once objects are out.
    assert_eq!(t.brier_static, n.brier_static);
    assert!(t.brier_static.is_some_and(|b| b > 0.0 && b < 1.0), "{t:?}");
    let information = |s: &fleet::FleetSummary| s.information_per_robot_hour.unwrap_or(0.0);

    // The pictures hold what their legends say.
    let picture = fleet::picture::warehouse_svg(world, news, 3);
    let count = |svg: &str, what: &str| svg.matches(what).count();
    assert_eq!(count(&picture, r#"class="change""#), news.events.len());
    let moved = news.paths.iter().filter(|p| p.len() > 1).count();
    assert!(moved >= 2, "both shift robots drove");
    assert_eq!(count(&picture, r#"class="path""#), moved);
    for entry in ["change never seen", "UWB anchor", "robot 1's path"] {
        assert!(picture.contains(entry), "the legend names {entry}");
    }
    // A title naming the variant and the seed, and a scale bar.
    assert!(
        picture.contains(r#"<text id="title""#) && picture.contains("news, first shift, seed 3")
    );
    assert!(picture.contains(r#"<g id="scale">"#) && picture.contains(">10 m</text>"));
    let detection = fleet::picture::detection_svg(&report.weeks, 3);
    assert!(detection.contains(r#"<text id="title""#) && detection.contains("2 variants, seed 3"));
    assert_eq!(count(&detection, r#"class="variant""#), 2);
    assert!(detection.contains(">tasks_only<") && detection.contains(">news<"));
    assert!(
        information(n) > information(t),
        "news {} against tasks only {}",
        information(n),
        information(t)
    );
}

/// Robot `robot`'s greedy plan from the dock to an aisle on the fleet's news at t = 0.
fn plan_on_news(world: &FleetWorld, mapper: &FleetMapper, robot: usize, name: &str) -> Plan {
    let news = mapper
        .news_scores(robot, name, 0.0, true)
        .expect("news scores");
    let mut coupled = world.planning.clone();
    coupled.information =
        Coupling::News.apply(&world.planning.information, &news, DEFAULT_NEWS_FLOOR);
    coupled.set_heuristic_compression(coupled.heuristic_compression);
    let request = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: [10.0, 3.0],
        goal: [27.6, 12.0],
        t_exec_s: 120.0,
        deadline_s: 5.0,
        model: PlannerModel::Greedy,
        params: Default::default(),
        seed: 7,
        map_version: None,
        shortest: Default::default(),
        seed_route: Vec::new(),
    };
    roam_planner::answer::answer(&coupled, &request, 1).expect("a plan")
}

/// The share of `b`'s cells that `a` also passes.
fn overlap(a: &Plan, b: &Plan) -> f64 {
    let a: BTreeSet<[u32; 2]> = a.cells.iter().copied().collect();
    let b: BTreeSet<[u32; 2]> = b.cells.iter().copied().collect();
    a.intersection(&b).count() as f64 / b.len().max(1) as f64
}

/// Two robots offered the same news at the same moment: without the first one's plan
/// reserved the second plans the very same path; with it, the second takes other cells.
#[test]
fn two_robots_offered_the_same_news_take_different_cells() {
    let world = world();
    let mut mapper = FleetMapper::new(world, 2, false, DEFAULT_NEWS_PRIOR).expect("mapper");
    let first = plan_on_news(world, &mapper, 0, "r1");
    let alike = plan_on_news(world, &mapper, 1, "r2");
    assert_eq!(first.cells, alike.cells, "the same news, the same plan");

    let radius_m = world.sim_params.sensing.observation_radius_m;
    mapper
        .reserve(
            world,
            "r1",
            &first.points,
            0.0,
            TimeModel::table_i().v_lin,
            radius_m,
        )
        .expect("reserve");
    let second = plan_on_news(world, &mapper, 1, "r2");
    let shared = overlap(&first, &second);
    assert!(
        shared < 0.6,
        "r2 passes {:.0}% of r1's cells: {} cells against {}",
        100.0 * shared,
        second.cells.len(),
        first.cells.len()
    );
    // r1's own plan keeps its news for r1.
    assert_eq!(plan_on_news(world, &mapper, 0, "r1").cells, first.cells);
}

/// The built-in warehouse's patrol, as an operator would lay it out: through every
/// aisle, but never where the anchors leave the robot without a fix (the north-east
/// gap), where the controller would hold it.
#[test]
fn the_operators_patrol_goes_through_every_aisle_and_round_the_anchor_gap() {
    let warehouse = world();
    let patrol = warehouse.patrol.as_ref().expect("the aisle patrol");
    let planning = &warehouse.planning;
    let max_peb_m = roam_controller::params::ApfParams::fleet().max_peb_m;
    let points = patrol.loop_points();
    let peb_at = |p: &[f64; 2]| {
        let cell = planning.cell_at(p[0], p[1]).expect("on the map");
        f64::from(planning.localizability[cell as usize])
    };
    let worst = points.iter().map(peb_at).fold(0.0, f64::max);
    assert!(
        worst <= max_peb_m,
        "the patrol drives where the PEB is {worst} m"
    );
    // The gap is there (so the test means something): the north main aisle's east end.
    assert!(peb_at(&[50.0, 34.0]) > max_peb_m);
    // Every aisle between the racks (x = 7.6 + 4 j) and the east aisle is driven
    // along its south stretch between the racks.
    for x in (1..=11).map(|j| 7.6 + 4.0 * f64::from(j)).chain([56.5]) {
        assert!(
            points
                .iter()
                .any(|p| (p[0] - x).abs() < 0.3 && (10.0..17.0).contains(&p[1])),
            "aisle x = {x} not patrolled"
        );
    }
    // Aisles the anchors cover end to end are driven to the north main aisle.
    assert!(points
        .iter()
        .any(|p| (p[0] - 11.6).abs() < 0.3 && p[1] > 33.0));
    // A loop: its last point is its first corner.
    assert_eq!(points.last(), points.first());
}
