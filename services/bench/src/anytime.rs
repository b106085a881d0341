//! `roam bench planner --anytime`: how good the plan is when a client needs it.
//!
//! On each trip (the built-in world to Goal 2, a round trip there, the depot, the
//! warehouse; budgets as in `--peer`: twice the fastest path's ETA, 60 s for a round
//! trip), the anytime planner (`model: anytime`: the greedy route at once, then the GA
//! seeded with it) plans with a deadline at each checkpoint (10, 30, 100, 300 and
//! 1000 ms by default) and once more to its end (the planner's default 2000 generations,
//! within the reference time), once per seed. Each run is the plan a client with that
//! deadline gets: a run stopped at 100 ms is not the 1000 ms run looked at early.
//!
//! The reference is the best plan found by any planner given [`REFERENCE_FACTOR`] times
//! the last checkpoint: the greedy planner, Model I's GA (up to 20,000 generations
//! within the time) and the anytime planner, each seed. A trip's best-known information is
//! the most any run of the trip found (checkpoints included), so a share is never
//! above 1. The figure is the distinct information of the driven path (0.2 m planning
//! cells, as `--peer` and `--optimality` count it); a plan not within its budget is
//! worth 0.
//!
//! Runs stopped by a deadline depend on the machine's speed, so only their seeds repeat,
//! not their answers; the medians over seeds are the figures.

use std::sync::atomic::AtomicBool;

use roam_planner::plan::{plan, PlanOutcome, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use serde::Serialize;

use crate::peer::{depot, fastest_eta};
use crate::planner::{builtin_world, GOAL, START};
use crate::scaling::{warehouse, WAREHOUSE_GOAL, WAREHOUSE_START};
use crate::{setup, BenchError};
use roam_experiments::progress::{Done, Progress};

/// The checkpoints when none are given, milliseconds.
pub const DEFAULT_CHECKPOINTS_MS: [f64; 5] = [10.0, 30.0, 100.0, 300.0, 1000.0];
/// The most checkpoints a run takes.
pub const MAX_CHECKPOINTS: usize = 16;
/// The latest checkpoint, milliseconds: the reference runs take ten times as long.
pub const MAX_CHECKPOINT_MS: f64 = 60_000.0;
/// The reference planners' time, as a multiple of the last checkpoint.
pub const REFERENCE_FACTOR: f64 = 10.0;
/// The checkpoint the goal is read at, and the goal: the median plan there holds at
/// least this share of the best-known information on every trip.
pub const GOAL_CHECKPOINT_MS: f64 = 100.0;
pub const GOAL_SHARE: f64 = 0.95;
/// Generations for the runs a deadline stops: ten times Table I's, about 10 s at the
/// paper's population on this machine, and within the planner's `max_plan_cost` on
/// every trip (more is refused there as too costly to start).
const UNBOUNDED_GENERATIONS: u32 = 20_000;
/// The planner's default generations (Table I), for the run to the end.
const END_GENERATIONS: u32 = 2000;

/// Why a checkpoint list cannot be measured.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum CheckpointError {
    #[error("no checkpoints: give at least one, in milliseconds (e.g. 10,30,100)")]
    Empty,
    #[error("{count} checkpoints; at most {MAX_CHECKPOINTS} are measured")]
    TooMany { count: usize },
    #[error("checkpoint {value} ms is not in (0, {MAX_CHECKPOINT_MS}] ms")]
    OutOfRange { value: f64 },
    #[error("checkpoints must increase: {before} ms then {after} ms")]
    Unordered { before: f64, after: f64 },
}

/// Checks a checkpoint list: 1 to [`MAX_CHECKPOINTS`] values in (0,
/// [`MAX_CHECKPOINT_MS`]] ms, strictly increasing.
pub fn check_checkpoints(checkpoints_ms: &[f64]) -> Result<(), CheckpointError> {
    if checkpoints_ms.is_empty() {
        return Err(CheckpointError::Empty);
    }
    if checkpoints_ms.len() > MAX_CHECKPOINTS {
        return Err(CheckpointError::TooMany {
            count: checkpoints_ms.len(),
        });
    }
    if let Some(&value) = checkpoints_ms
        .iter()
        .find(|v| !(v.is_finite() && **v > 0.0 && **v <= MAX_CHECKPOINT_MS))
    {
        return Err(CheckpointError::OutOfRange { value });
    }
    match checkpoints_ms.windows(2).find(|w| w[1] <= w[0]) {
        Some(w) => Err(CheckpointError::Unordered {
            before: w[0],
            after: w[1],
        }),
        None => Ok(()),
    }
}

/// One checkpoint of a trip: the median over seeds.
#[derive(Debug, Clone, Serialize)]
pub struct Checkpoint {
    /// The deadline, ms; `None` for the run to the end.
    pub deadline_ms: Option<f64>,
    pub distinct_information_median: f64,
    /// The median run's share of the trip's best-known information.
    pub share_median: f64,
    pub share_min: f64,
    /// The wall time of the median run, ms.
    pub wall_ms_median: f64,
    /// What produced each seed's plan (`greedy`, `ga`, `via_seed`, `shortest`).
    pub found_by: Vec<&'static str>,
}

#[derive(Debug, Clone, Serialize)]
pub struct AnytimeTrip {
    pub trip: String,
    pub budget_s: f64,
    pub checkpoints: Vec<Checkpoint>,
    /// The run to the end (the planner's default generations).
    pub end: Checkpoint,
    /// The most distinct information any run of this trip found.
    pub best_known: f64,
    /// Which reference planner found the most, median over seeds (`greedy`, `model1`,
    /// `anytime`), and its information.
    pub reference_median: f64,
    pub reference_best_by: &'static str,
}

#[derive(Debug, Clone, Serialize)]
pub struct AnytimeBench {
    pub trips: Vec<AnytimeTrip>,
    pub runs: usize,
    pub reference_s: f64,
    /// The share at [`GOAL_CHECKPOINT_MS`] on the trip where it is lowest (absent when
    /// that checkpoint was not measured), and whether it meets [`GOAL_SHARE`].
    pub goal_checkpoint_ms: f64,
    pub goal_share: f64,
    pub worst_share_at_goal_checkpoint: Option<f64>,
    pub goal_met: Option<bool>,
}

/// A trip: where from, where to, on which world.
#[derive(Debug)]
pub struct Trip<'w> {
    pub name: &'static str,
    pub world: &'w World,
    pub start: [f64; 2],
    pub goal: [f64; 2],
}

/// Runs the benchmark on the four trips (see the module doc); `progress` after each trip.
pub fn anytime(
    checkpoints_ms: &[f64],
    runs: usize,
    progress: Progress<'_>,
) -> Result<AnytimeBench, BenchError> {
    let builtin = builtin_world()?;
    let depot = depot()?;
    let (inflated, information) = warehouse();
    let warehouse = World::at_resolution(&inflated, &information, 0.25, 0.2).map_err(setup)?;
    let trips = [
        Trip {
            name: "built-in, Goal 2",
            world: &builtin,
            start: START,
            goal: GOAL,
        },
        Trip {
            name: "built-in, round trip",
            world: &builtin,
            start: START,
            goal: START,
        },
        Trip {
            name: "depot",
            world: &depot,
            start: [3.0, 8.0],
            goal: [20.0, 9.0],
        },
        Trip {
            name: "warehouse 3 cm",
            world: &warehouse,
            start: WAREHOUSE_START,
            goal: WAREHOUSE_GOAL,
        },
    ];
    anytime_on(&trips, checkpoints_ms, runs, progress)
}

/// The benchmark on `trips`; the checkpoints and runs are checked here, before the
/// first plan.
pub fn anytime_on(
    trips: &[Trip<'_>],
    checkpoints_ms: &[f64],
    runs: usize,
    progress: Progress<'_>,
) -> Result<AnytimeBench, BenchError> {
    check_checkpoints(checkpoints_ms).map_err(setup)?;
    if runs == 0 {
        return Err(BenchError::Setup("--runs must be at least 1".into()));
    }
    let last_ms = checkpoints_ms.last().copied().unwrap_or(GOAL_CHECKPOINT_MS);
    let reference_s = REFERENCE_FACTOR * last_ms / 1000.0;
    let mut out = Vec::new();
    progress(Done::of("trips", "trips", 0, trips.len()));
    for trip in trips {
        out.push(one_trip(trip, checkpoints_ms, runs, reference_s)?);
        progress(Done::of("trips", "trips", out.len(), trips.len()));
    }
    let at_goal: Vec<f64> = out
        .iter()
        .filter_map(|t| {
            t.checkpoints
                .iter()
                .find(|c| c.deadline_ms == Some(GOAL_CHECKPOINT_MS))
                .map(|c| c.share_median)
        })
        .collect();
    let worst = (at_goal.len() == out.len() && !out.is_empty())
        .then(|| at_goal.iter().copied().fold(f64::INFINITY, f64::min));
    Ok(AnytimeBench {
        trips: out,
        runs,
        reference_s,
        goal_checkpoint_ms: GOAL_CHECKPOINT_MS,
        goal_share: GOAL_SHARE,
        worst_share_at_goal_checkpoint: worst,
        goal_met: worst.map(|w| w >= GOAL_SHARE),
    })
}

/// One run's worth: its information (0 unless within budget), wall time and source.
struct Run {
    information: f64,
    wall_ms: f64,
    found_by: &'static str,
}

fn run(world: &World, spec: &PlanSpec) -> Result<Run, BenchError> {
    let started = std::time::Instant::now();
    let outcome: PlanOutcome =
        plan(world, spec, &AtomicBool::new(false), |_, _| {}).map_err(setup)?;
    Ok(Run {
        information: if outcome.within_budget {
            outcome.metrics.distinct_information
        } else {
            0.0
        },
        wall_ms: crate::ms(started.elapsed()),
        found_by: outcome.source.as_str(),
    })
}

fn one_trip(
    trip: &Trip<'_>,
    checkpoints_ms: &[f64],
    runs: usize,
    reference_s: f64,
) -> Result<AnytimeTrip, BenchError> {
    let (world, start, goal) = (trip.world, trip.start, trip.goal);
    let budget_s = if start == goal {
        60.0
    } else {
        2.0 * fastest_eta(world, start, goal)?
    };
    let spec = |model: PlannerModel, generations: u32, deadline_s: f64, seed: u64| PlanSpec {
        deadline_s,
        ..PlanSpec::batch(start, goal, budget_s, model, generations, seed)
    };
    let seeds = 0..runs as u64;
    let mut at: Vec<Vec<Run>> = Vec::new();
    for &ms in checkpoints_ms {
        let runs = seeds
            .clone()
            .map(|seed| {
                let s = spec(
                    PlannerModel::Anytime,
                    UNBOUNDED_GENERATIONS,
                    ms / 1000.0,
                    seed,
                );
                run(world, &s)
            })
            .collect::<Result<Vec<_>, _>>()?;
        at.push(runs);
    }
    let end = seeds
        .clone()
        .map(|seed| {
            let s = spec(PlannerModel::Anytime, END_GENERATIONS, reference_s, seed);
            run(world, &s)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let references = [
        ("greedy", PlannerModel::Greedy),
        ("model1", PlannerModel::Model1),
        ("anytime", PlannerModel::Anytime),
    ];
    let mut best_reference = Vec::new();
    for seed in seeds.clone() {
        let mut best = (0.0f64, "greedy");
        for (name, model) in references {
            let s = spec(model, UNBOUNDED_GENERATIONS, reference_s, seed);
            let r = run(world, &s)?;
            if r.information > best.0 {
                best = (r.information, name);
            }
        }
        best_reference.push(best);
    }
    let best_known = at
        .iter()
        .flatten()
        .chain(&end)
        .map(|r| r.information)
        .chain(best_reference.iter().map(|b| b.0))
        .fold(0.0, f64::max);
    best_reference.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (reference_median, reference_best_by) = best_reference[best_reference.len() / 2];
    let summary = |deadline_ms: Option<f64>, runs: &[Run]| {
        let share = |v: f64| {
            if best_known > 0.0 {
                v / best_known
            } else {
                1.0
            }
        };
        let mut info: Vec<f64> = runs.iter().map(|r| r.information).collect();
        info.sort_by(f64::total_cmp);
        let mut wall: Vec<f64> = runs.iter().map(|r| r.wall_ms).collect();
        wall.sort_by(f64::total_cmp);
        let median = info[info.len() / 2];
        Checkpoint {
            deadline_ms,
            distinct_information_median: median,
            share_median: share(median),
            share_min: share(info[0]),
            wall_ms_median: wall[wall.len() / 2],
            found_by: runs.iter().map(|r| r.found_by).collect(),
        }
    };
    Ok(AnytimeTrip {
        trip: trip.name.to_owned(),
        budget_s,
        checkpoints: checkpoints_ms
            .iter()
            .zip(&at)
            .map(|(&ms, runs)| summary(Some(ms), runs))
            .collect(),
        end: summary(None, &end),
        best_known,
        reference_median,
        reference_best_by,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_checkpoint_list_must_be_short_positive_and_increasing() {
        assert_eq!(check_checkpoints(&DEFAULT_CHECKPOINTS_MS), Ok(()));
        assert_eq!(check_checkpoints(&[]), Err(CheckpointError::Empty));
        assert_eq!(
            check_checkpoints(&[30.0, 10.0]),
            Err(CheckpointError::Unordered {
                before: 30.0,
                after: 10.0
            })
        );
        assert_eq!(
            check_checkpoints(&[10.0, 10.0]),
            Err(CheckpointError::Unordered {
                before: 10.0,
                after: 10.0
            })
        );
        for bad in [0.0, -5.0, f64::NAN, MAX_CHECKPOINT_MS * 2.0] {
            assert!(
                matches!(
                    check_checkpoints(&[bad]),
                    Err(CheckpointError::OutOfRange { .. })
                ),
                "{bad}"
            );
        }
        let many: Vec<f64> = (1..=17).map(f64::from).collect();
        assert_eq!(
            check_checkpoints(&many),
            Err(CheckpointError::TooMany { count: 17 })
        );
    }

    #[test]
    fn shares_are_of_the_best_known_and_the_goal_is_read_off_them() {
        let world = builtin_world().expect("built-in world");
        let trips = [Trip {
            name: "built-in, Goal 2",
            world: &world,
            start: START,
            goal: GOAL,
        }];
        let bench = anytime_on(&trips, &[5.0, 100.0], 1, &|_| {}).expect("bench");
        let trip = &bench.trips[0];
        assert_eq!(trip.checkpoints.len(), 2);
        assert!(trip.best_known > 0.0);
        for c in trip.checkpoints.iter().chain([&trip.end]) {
            assert!((0.0..=1.0).contains(&c.share_median), "{c:?}");
            assert_eq!(c.found_by.len(), 1);
            let expected = c.distinct_information_median / trip.best_known;
            assert!((c.share_median - expected).abs() < 1e-12);
        }
        assert!(trip.reference_median <= trip.best_known);
        assert_eq!(bench.reference_s, 1.0);
        let worst = bench
            .worst_share_at_goal_checkpoint
            .expect("100 ms measured");
        assert_eq!(worst, trip.checkpoints[1].share_median);
        assert_eq!(bench.goal_met, Some(worst >= GOAL_SHARE));
        // Without the goal's checkpoint there is no verdict.
        let none = anytime_on(&trips, &[5.0], 1, &|_| {}).expect("bench");
        assert_eq!(
            (none.worst_share_at_goal_checkpoint, none.goal_met),
            (None, None)
        );
    }
}
