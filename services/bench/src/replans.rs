//! `roam bench planner --replans`: what a replan costs on the day world.
//!
//! The executive's day runs in batch (`roam reproduce mission`'s own code: the
//! executive's window machine, the sim, localization, the controller) for `days` days
//! of the shipped configuration, and every request the executive makes is kept. Each
//! replan among them (a request with a `seed_route`: the slack and behind replans) is
//! answered again here by the planner's own code, timed:
//!
//! - **seeded**: as the executive asks it: the route left as the seed, the executive's
//!   `replan_generations`;
//! - **from scratch**: no seed, the first plan's generations (the executive's
//!   `max_generations`): what the seed and the fewer generations save.
//!
//! - **map change**: each replan again, on the day world with a pallet dropped on the
//!   seed route ahead ([`PALLET_AHEAD_M`] along it; blocked within
//!   [`PALLET_BLOCKS_M`], a 0.3 m pallet inflated by the planner's default
//!   `obstacle_inflation_m`), as the executive asks when what the fleet has seen blocks
//!   its route (`map_changed`): seeded with the route left, which the planner repairs
//!   round the pallet (`roam_planner::remainder`), against the same from scratch.
//!
//! The latency is the planner's compute time for the answer, in process with the
//! service's evaluation threads, on the day's static map (the batch couples the change
//! layer, which changes the scores, not the work); the service adds its queue and a
//! loopback round trip (under a millisecond: `roam bench planner` through Zenoh). Its
//! p99 against [`GOAL_P99_MS`] is the verdict. The information figure is the plan's
//! distinct information, seeded against from scratch, per replan: what the shorter
//! search gives up, or gains.

use std::time::Instant;

use roam_experiments::progress::{Done, Progress};
use roam_experiments::reproduce::mission::days::{self, DaysOptions, Variant};
use roam_mission::config::ExecutiveConfig;
use roam_mission::window::{seen_world, SeenObstacles};
use roam_planner::answer::answer;
use roam_planner::world::World;
use roam_proto::planner::PlanRequest;
use serde::Serialize;

use crate::load::percentile;
use crate::{ms, setup, BenchError};

/// The goal: a replan's p99 latency on the day world, milliseconds.
pub const GOAL_P99_MS: f64 = 50.0;
/// The most days the benchmark runs.
pub const MAX_DAYS: usize = 100;
/// How far along a replan's seed route the map-change case drops its pallet, metres.
pub const PALLET_AHEAD_M: f64 = 2.0;
/// How far round the pallet's centre the map-change case blocks, metres: a pallet of
/// 0.3 m radius and the planner's default `obstacle_inflation_m` of 0.3 m.
pub const PALLET_BLOCKS_M: f64 = 0.6;

/// Latencies of one way of replanning, milliseconds.
#[derive(Debug, Clone, Serialize)]
pub struct Latency {
    pub generations: Option<u32>,
    pub p50_ms: f64,
    pub p99_ms: f64,
    pub max_ms: f64,
}

/// The benchmark's report.
#[derive(Debug, Clone, Serialize)]
pub struct ReplanBench {
    pub days: usize,
    /// Requests the executive made through the days, and the replans among them.
    pub requests: usize,
    pub replans: usize,
    /// Replans whose seed route the planner joined to its grid and planned from.
    pub seed_routes_used: usize,
    /// Replans whose answer is the seed route unchanged (nothing fitter was found).
    pub answered_with_the_route: usize,
    pub seeded: Latency,
    pub from_scratch: Latency,
    /// Median and worst, over replans, of the seeded plan's distinct information over
    /// the plan from scratch.
    pub information_ratio_median: f64,
    pub information_ratio_worst: f64,
    pub goal_p99_ms: f64,
    pub goal_met: bool,
    /// The same replans with a pallet on the route ahead (module doc).
    pub map_change: MapChangeReplans,
}

/// Replans after a pallet landed on the route ahead.
#[derive(Debug, Clone, Serialize)]
pub struct MapChangeReplans {
    /// Replans with room for a pallet on the seed route (at least [`PALLET_AHEAD_M`]
    /// of it, the pallet clear of the start and the task).
    pub replans: usize,
    /// Whose seed route crossed the pallet and was repaired round it and used.
    pub seed_routes_repaired: usize,
    pub seeded: Latency,
    pub from_scratch: Latency,
    pub information_ratio_median: f64,
    pub goal_met: bool,
}

/// Runs `days` days of the shipped executive and times their replans.
pub fn replans(days: usize, progress: Progress<'_>) -> Result<ReplanBench, BenchError> {
    if days == 0 || days > MAX_DAYS {
        return Err(BenchError::Setup(format!(
            "--runs {days}: give 1 to {MAX_DAYS} (MAX_DAYS) days"
        )));
    }
    let options = DaysOptions {
        days,
        variants: vec![Variant::Executive],
        ..DaysOptions::default()
    };
    let world = days::DayWorld::new(&options.site).map_err(setup)?;
    progress(Done::of("days", "days", 0, days));
    let report = days::run(&options, progress).map_err(setup)?;
    let config = days::day::day_config(&world, Variant::Executive, &options, 0);
    let asked: Vec<&PlanRequest> = report.results.iter().flat_map(|r| &r.asked).collect();
    let replans: Vec<&PlanRequest> = asked
        .iter()
        .copied()
        .filter(|r| !r.seed_route.is_empty())
        .collect();
    let threads = roam_planner::ga::default_threads();
    let (mut seeded_ms, mut scratch_ms, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    let (mut used, mut kept) = (0, 0);
    for (n, request) in replans.iter().enumerate() {
        let started = Instant::now();
        let seeded = answer(&world.planning, request, threads).map_err(setup)?;
        seeded_ms.push(ms(started.elapsed()));
        let scratch_request = from_scratch(request, &config);
        let started = Instant::now();
        let scratch = answer(&world.planning, &scratch_request, threads).map_err(setup)?;
        scratch_ms.push(ms(started.elapsed()));
        used += usize::from(seeded.seed_route_used == Some(true));
        kept += usize::from(seeded.found_by.as_deref() == Some("remainder"));
        if scratch.distinct_information > 0.0 {
            ratios.push(seeded.distinct_information / scratch.distinct_information);
        }
        progress(Done::of("replans", "replans", n + 1, replans.len()));
    }
    let map_change = map_change_replans(&world.planning, &replans, &config, threads, progress)?;
    let seeded = latency(config.replan_generations(), &mut seeded_ms);
    let from_scratch = latency(config.max_generations, &mut scratch_ms);
    let goal_met = !replans.is_empty() && seeded.p99_ms <= GOAL_P99_MS;
    Ok(ReplanBench {
        days,
        requests: asked.len(),
        replans: replans.len(),
        seed_routes_used: used,
        answered_with_the_route: kept,
        information_ratio_median: percentile(&mut ratios, 0.5),
        information_ratio_worst: ratios.iter().copied().reduce(f64::min).unwrap_or(0.0),
        seeded,
        from_scratch,
        goal_p99_ms: GOAL_P99_MS,
        goal_met,
        map_change,
    })
}

/// The map-change case (module doc): each replan on `world` with a pallet on its seed
/// route ahead, seeded and from scratch.
fn map_change_replans(
    world: &World,
    replans: &[&PlanRequest],
    config: &ExecutiveConfig,
    threads: usize,
    progress: Progress<'_>,
) -> Result<MapChangeReplans, BenchError> {
    let (mut seeded_ms, mut scratch_ms, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    let (mut cases, mut repaired) = (0, 0);
    for (n, request) in replans.iter().enumerate() {
        progress(Done::of("map-change replans", "replans", n, replans.len()));
        let Some(pallet) = point_along(&request.seed_route, PALLET_AHEAD_M) else {
            continue;
        };
        let clear_of =
            |p: [f64; 2]| (p[0] - pallet[0]).hypot(p[1] - pallet[1]) > 2.0 * PALLET_BLOCKS_M;
        if !(clear_of(request.start) && clear_of(request.goal)) {
            continue;
        }
        let set = SeenObstacles {
            points: vec![pallet],
            clearance_m: PALLET_BLOCKS_M,
        };
        let Some(blocked) = seen_world(world, &set) else {
            continue;
        };
        cases += 1;
        let started = Instant::now();
        let seeded = answer(&blocked, request, threads).map_err(setup)?;
        seeded_ms.push(ms(started.elapsed()));
        let scratch_request = from_scratch(request, config);
        let started = Instant::now();
        let scratch = answer(&blocked, &scratch_request, threads).map_err(setup)?;
        scratch_ms.push(ms(started.elapsed()));
        repaired += usize::from(seeded.seed_route_used == Some(true));
        if scratch.distinct_information > 0.0 {
            ratios.push(seeded.distinct_information / scratch.distinct_information);
        }
    }
    let seeded = latency(config.replan_generations(), &mut seeded_ms);
    Ok(MapChangeReplans {
        replans: cases,
        seed_routes_repaired: repaired,
        goal_met: cases > 0 && seeded.p99_ms <= GOAL_P99_MS,
        seeded,
        from_scratch: latency(config.max_generations, &mut scratch_ms),
        information_ratio_median: percentile(&mut ratios, 0.5),
    })
}

/// `request` without its seed, at the first plan's generations.
fn from_scratch(request: &PlanRequest, config: &ExecutiveConfig) -> PlanRequest {
    PlanRequest {
        seed_route: Vec::new(),
        params: roam_proto::planner::GaOverrides {
            max_generations: config.max_generations,
            ..request.params.clone()
        },
        ..request.clone()
    }
}

/// The point `along_m` metres along `route`, if it is that long.
fn point_along(route: &[[f64; 2]], along_m: f64) -> Option<[f64; 2]> {
    let mut left = along_m;
    for w in route.windows(2) {
        let step = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
        if step >= left && step > 0.0 {
            let t = left / step;
            return Some([
                w[0][0] + t * (w[1][0] - w[0][0]),
                w[0][1] + t * (w[1][1] - w[0][1]),
            ]);
        }
        left -= step;
    }
    None
}

fn latency(generations: Option<u32>, samples: &mut [f64]) -> Latency {
    Latency {
        generations,
        p50_ms: percentile(samples, 0.5),
        p99_ms: percentile(samples, 0.99),
        max_ms: samples.iter().copied().fold(0.0, f64::max),
    }
}
