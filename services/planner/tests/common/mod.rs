//! Worlds for the planner's tests.

use roam_map_server::map_file;
use roam_planner::params::GaParams;
use std::sync::atomic::AtomicBool;

use roam_planner::plan::{plan, PlanOutcome, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use roam_world::grid::Grid;
use roam_world::layers::inflate;
use roam_world::DEFAULT_MAX_CELLS;

/// The built-in 20 × 20 m downtime world, inflated by its robot radius.
#[allow(dead_code)]
pub fn builtin_world() -> World {
    let content = map_file::builtin(DEFAULT_MAX_CELLS).expect("builtin");
    let inflated = inflate(
        &content.occupancy,
        content.robot_radius_m.unwrap_or(0.2),
        65,
    );
    let information = content.information.expect("information");
    World::new(&inflated, &information, 0.25).expect("world")
}

/// A scenario of `config/scenarios/` as the planner sees it: its occupancy inflated
/// by its robot radius, its information layer.
#[allow(dead_code)]
pub fn scenario_world(file: &str) -> World {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../config/scenarios")
        .join(file);
    let scenario = roam_world::scenario::load(&path, DEFAULT_MAX_CELLS).expect("scenario");
    let inflated = inflate(
        &scenario.occupancy,
        scenario.file.robot_radius_m.unwrap_or(0.2),
        65,
    );
    World::new(&inflated, &scenario.information, 0.25).expect("world")
}

/// An open `w × h` world at 0.2 m with walls around and a score-`score` square.
#[allow(dead_code)]
pub fn open_world(w: u32, h: u32) -> World {
    let meta = roam_proto::map::GridMeta {
        width: w,
        height: h,
        resolution: 0.2,
        origin: roam_proto::map::Origin::default(),
    };
    let occupancy = Grid::filled(meta, 0i8);
    let mut information = Grid::filled(meta, 0u8);
    for y in h as usize / 2..h as usize {
        for x in w as usize / 2..w as usize {
            information.cells[y * w as usize + x] = 60;
        }
    }
    World::new(&occupancy, &information, 0.25).expect("world")
}

#[allow(dead_code)]
/// Paper 000 Eq. 2 written again from the cell centres in metres, without the
/// planner's code: v_lin · Σ segment lengths + v_ang · Σ |heading changes|.
pub fn independent_eta(world: &World, params: &GaParams, path: &[u32]) -> f64 {
    let points: Vec<(f64, f64)> = path.iter().map(|&c| world.center(c)).collect();
    let mut distance = 0.0;
    let mut turning = 0.0;
    let mut previous_heading: Option<f64> = None;
    for pair in points.windows(2) {
        let (dx, dy) = (pair[1].0 - pair[0].0, pair[1].1 - pair[0].1);
        distance += dx.hypot(dy);
        let heading = dy.atan2(dx);
        if let Some(previous) = previous_heading {
            let mut turn = (heading - previous).abs();
            if turn > std::f64::consts::PI {
                turn = 2.0 * std::f64::consts::PI - turn;
            }
            turning += turn;
        }
        previous_heading = Some(heading);
    }
    params.v_lin * distance + params.v_ang * turning
}

#[allow(dead_code)]
/// The geometry every returned path must have, checked independently of the planner.
pub fn check_geometry(world: &World, spec: &PlanSpec, outcome: &PlanOutcome) {
    let path = &outcome.path;
    let start = world.cell_at(spec.start[0], spec.start[1]);
    match start.filter(|&s| world.is_traversable(s)) {
        Some(s) => assert_eq!(path.first().copied(), Some(s), "starts at S"),
        // A start in an obstacle's edge plans from the nearest free cell within
        // START_SNAP_M.
        None => {
            let (first, start) = (world.xy(path[0]), world.xy(start.expect("on the map")));
            let apart = (first.0 as f64 - start.0 as f64).hypot(first.1 as f64 - start.1 as f64);
            assert!(
                apart * world.meta.resolution <= roam_planner::plan::START_SNAP_M + 1e-9,
                "starts within START_SNAP_M of S"
            );
        }
    }
    for &cell in path {
        assert!(
            world.is_traversable(cell),
            "cell {:?} is not free",
            world.xy(cell)
        );
    }
    for pair in path.windows(2) {
        let ((ax, ay), (bx, by)) = (world.xy(pair[0]), world.xy(pair[1]));
        assert_eq!(
            ax.abs_diff(bx).max(ay.abs_diff(by)),
            1,
            "8-connected step {:?} → {:?}",
            (ax, ay),
            (bx, by)
        );
        if ax != bx && ay != by {
            // No corner cutting: both orthogonal neighbours are free.
            assert!(
                world.is_traversable(world.cell(bx, ay))
                    && world.is_traversable(world.cell(ax, by))
            );
        }
    }
    // An independent recomputation of the claims: the goal and the budget.
    let goal = world.cell_at(spec.goal[0], spec.goal[1]);
    assert_eq!(outcome.reaches_goal, path.last().copied() == goal);
    let eta = independent_eta(world, &spec.params, path);
    assert!(
        (eta - outcome.t_eta_s).abs() < 1e-6,
        "eta {eta} vs {}",
        outcome.t_eta_s
    );
    assert_eq!(outcome.within_budget, eta <= spec.t_exec_s);
}

/// A plan of `spec` on `world` that must succeed, never cancelled.
#[allow(dead_code)]
pub fn run(world: &World, spec: &PlanSpec) -> PlanOutcome {
    plan(world, spec, &AtomicBool::new(false), |_, _| {}).expect("plan")
}

/// `model` from `start` to `goal` in `t_exec_s`, population 60, `generations`, two
/// evaluation threads: a plan small enough for a test.
#[allow(dead_code)]
pub fn small_spec(
    model: PlannerModel,
    start: [f64; 2],
    goal: [f64; 2],
    t_exec_s: f64,
    seed: u64,
    generations: u32,
) -> PlanSpec {
    let mut spec = PlanSpec::batch(start, goal, t_exec_s, model, generations, seed);
    spec.params.population = 60;
    spec.threads = 2;
    spec
}
