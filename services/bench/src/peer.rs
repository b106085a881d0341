//! `roam bench planner --peer`: the greedy planner (model `greedy`) against Model I at
//! equal wall time, on several worlds (issue 16).
//!
//! Each trip is planned by Model I with the paper's workload (population 200, 2000
//! generations, seeds 0..runs, its median wall time T); by `greedy` with a deadline of T
//! (it stops earlier when nothing improves: it has no randomness, one run); and by
//! Model I again with a deadline of the greedy planner's own wall time (generations
//! unbounded within it). Budgets are twice the fastest path's ETA (a round trip: 60 s).
//! The figure compared is the information of the distinct planning cells seen along
//! the driven path (`distinct_information`, 0.2 m cells) and the fitness (Eq. 1, Model
//! I); `winner` names the planner with more information at equal time.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use roam_world::grid::Grid;
use serde::Serialize;

use crate::{setup, BenchError};

use crate::planner::{builtin_world, GOAL, START};
use crate::scaling::{warehouse, WAREHOUSE_GOAL, WAREHOUSE_START};
use roam_experiments::progress::{Done, Progress};

#[derive(Debug, Clone, Serialize)]
pub struct PlannerRun {
    pub seconds: f64,
    pub distinct_information: f64,
    pub fitness: f64,
    pub t_eta_s: f64,
    pub within_budget: bool,
}

#[derive(Debug, Clone, Serialize)]
pub struct PeerTrip {
    pub world: String,
    pub start: [f64; 2],
    pub goal: [f64; 2],
    pub budget_s: f64,
    /// Model I, 2000 generations (medians over the seeds).
    pub model1: PlannerRun,
    /// Greedy with Model I's wall time as its deadline.
    pub greedy: PlannerRun,
    /// Model I with the greedy planner's wall time as its deadline (median).
    pub model1_at_greedy_time: PlannerRun,
    /// `greedy` or `model1`: more distinct information, Model I at its 2000 generations
    /// against greedy given as long.
    pub winner_at_model1_time: String,
    /// The same with Model I cut to the greedy planner's time.
    pub winner_at_greedy_time: String,
}

#[derive(Debug, Clone, Serialize)]
pub struct PeerBench {
    pub trips: Vec<PeerTrip>,
    pub runs: usize,
}

fn median_run(mut runs: Vec<PlannerRun>) -> PlannerRun {
    runs.sort_by(|a, b| a.distinct_information.total_cmp(&b.distinct_information));
    let mid = runs.len() / 2;
    let mut seconds: Vec<f64> = runs.iter().map(|r| r.seconds).collect();
    seconds.sort_by(f64::total_cmp);
    PlannerRun {
        seconds: seconds[mid],
        ..runs[mid].clone()
    }
}

fn once(world: &World, spec: &PlanSpec) -> Result<PlannerRun, BenchError> {
    let started = Instant::now();
    let outcome = plan(world, spec, &AtomicBool::new(false), |_, _| {}).map_err(setup)?;
    Ok(PlannerRun {
        seconds: started.elapsed().as_secs_f64(),
        distinct_information: outcome.metrics.distinct_information,
        fitness: outcome.fitness.total,
        t_eta_s: outcome.t_eta_s,
        within_budget: outcome.within_budget,
    })
}

fn winner(model1: &PlannerRun, greedy: &PlannerRun) -> String {
    if greedy.distinct_information > model1.distinct_information {
        "greedy"
    } else if greedy.distinct_information < model1.distinct_information {
        "model1"
    } else {
        "tie"
    }
    .to_owned()
}

fn trip(
    name: &str,
    world: &World,
    start: [f64; 2],
    goal: [f64; 2],
    runs: usize,
) -> Result<PeerTrip, BenchError> {
    let floor = fastest_eta(world, start, goal)?;
    let budget_s = if start == goal { 60.0 } else { 2.0 * floor };
    let model1 = median_run(
        (0..runs as u64)
            .map(|seed| {
                once(
                    world,
                    &PlanSpec::batch(start, goal, budget_s, PlannerModel::Model1, 2000, seed),
                )
            })
            .collect::<Result<_, _>>()?,
    );
    let greedy = once(
        world,
        &PlanSpec {
            deadline_s: model1.seconds.max(0.001),
            ..PlanSpec::batch(start, goal, budget_s, PlannerModel::Greedy, 1, 0)
        },
    )?;
    let model1_at_greedy_time = median_run(
        (0..runs as u64)
            .map(|seed| {
                once(
                    world,
                    &PlanSpec {
                        deadline_s: greedy.seconds.max(0.001),
                        ..PlanSpec::batch(start, goal, budget_s, PlannerModel::Model1, 20_000, seed)
                    },
                )
            })
            .collect::<Result<_, _>>()?,
    );
    Ok(PeerTrip {
        world: name.to_owned(),
        start,
        goal,
        budget_s,
        winner_at_model1_time: winner(&model1, &greedy),
        winner_at_greedy_time: winner(&model1_at_greedy_time, &greedy),
        model1,
        greedy,
        model1_at_greedy_time,
    })
}

pub(crate) fn fastest_eta(
    world: &World,
    start: [f64; 2],
    goal: [f64; 2],
) -> Result<f64, BenchError> {
    let spec = PlanSpec::batch(start, goal, 86_400.0, PlannerModel::Shortest, 1, 0);
    Ok(plan(world, &spec, &AtomicBool::new(false), |_, _| {})
        .map_err(setup)?
        .t_eta_s)
}

/// The depot scenario (Nav2's depot map at 5 cm with zones of interest), planned at
/// 0.2 m.
pub(crate) fn depot() -> Result<World, BenchError> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/scenarios/depot.yaml");
    let scenario =
        roam_world::scenario::load(&path, roam_world::DEFAULT_MAX_CELLS).map_err(setup)?;
    let inflated: Grid<i8> = roam_world::layers::inflate(
        &scenario.occupancy,
        scenario.file.robot_radius_m.unwrap_or(0.2),
        65,
    );
    World::at_resolution(&inflated, &scenario.information, 0.25, 0.2).map_err(setup)
}

/// Runs the comparison (see the module doc); `progress` after each trip.
pub fn peer(runs: usize, progress: Progress<'_>) -> Result<PeerBench, BenchError> {
    let builtin = builtin_world()?;
    let depot = depot()?;
    let (inflated, information) = warehouse();
    let warehouse = World::at_resolution(&inflated, &information, 0.25, 0.2).map_err(setup)?;
    let mut trips = Vec::new();
    let all = [
        ("built-in, Goal 2", &builtin, START, GOAL),
        ("built-in, Goal 1", &builtin, START, [-2.0, 4.0]),
        ("built-in, round trip", &builtin, START, START),
        ("built-in, far corner", &builtin, START, [8.0, 8.0]),
        ("depot", &depot, [3.0, 8.0], [20.0, 9.0]),
        ("depot, round trip", &depot, [3.0, 8.0], [3.0, 8.0]),
        (
            "warehouse 3 cm",
            &warehouse,
            WAREHOUSE_START,
            WAREHOUSE_GOAL,
        ),
    ];
    progress(Done::of("trips", "trips", 0, all.len()));
    for (name, world, start, goal) in all {
        trips.push(trip(name, world, start, goal, runs)?);
        progress(Done::of("trips", "trips", trips.len(), all.len()));
    }
    Ok(PeerBench { trips, runs })
}
