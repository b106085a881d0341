//! `roam reproduce mission --days N`: the executive's day in batch. The demo's day
//! ([`roam_mission::tasks::day`] on [`roam_mission::tasks::DAY_SCENARIO`]: four
//! windows, one a round trip, a cart on the docks, a north-east room no anchor covers)
//! is run N times per variant with the shipped code and no network:
//!
//! - **the executive**: its own window machine ([`roam_mission::window`]), each
//!   variant a configuration of it ([`Variant`], [`roam_mission::config::ExecutiveConfig`]),
//!   driven as the live executive drives it ([`day`]);
//! - **planning**: the very request the executive sends, answered by the planner's own
//!   code on the map the planner service holds ([`planning`]); an answer reaches the
//!   window `plan_wall_s` (`replan_wall_s` for a replan seeded with the route left;
//!   cut to the plan's deadline) at the clock's `rate` later, while
//!   the robot drives on, as in the demo;
//! - **driving**: the sim, localization's tracker and the APF controller one step at a
//!   time ([`crate::closed_loop::stepper::Stepper`]), the mapper's change map fed the
//!   robot's observation every step ([`robot`]); mission time is sim time.
//!
//! **Common random numbers**: a day's sim seed and its plans' seed depend on the day,
//! never on the variant, so every variant of a day meets the same range and motion
//! noise step by step. Days are independent: each starts from the time model's prior
//! and an empty change map. The same options give the same report bit for bit,
//! whatever the number of threads (`jobs`).
//!
//! Measured per window ([`measure::WindowResult`]): the share of the window driven, late
//! arrivals, the information driven (paper 000's distinct cells on the static map,
//! along the true path) and planned, the change seen, the PEB, holds and recoveries, and
//! the time model's prediction error; then per variant and window of the day
//! ([`summary`]), against the goals with verdicts computed from the figures ([`goals`]),
//! as a table ([`table`]).

pub mod day;
pub mod goals;
pub mod measure;
pub mod planning;
pub mod robot;
pub mod stats;
pub mod summary;
pub mod table;
pub mod variant;
pub mod world;

mod error;
mod options;

#[cfg(test)]
mod tests;

use crate::parallel::run_in_order;
use crate::progress::{Done, Progress};

use serde::Serialize;

pub use day::DayResult;
pub use error::DaysError;
pub use goals::{Goal, Verdict};
pub use options::DaysOptions;
pub use summary::{Effect, Paired, VariantSummary};
pub use variant::Variant;
pub use world::DayWorld;

/// The most days one batch runs.
pub const MAX_DAYS: usize = 10_000;

/// The most wall seconds a curious plan may cost (the planner's longest deadline).
pub const MAX_PLAN_WALL_S: f64 = 600.0;

/// The fastest clock a batch may assume, mission seconds per wall second.
pub const MAX_RATE: f64 = 1000.0;

/// The batch's report: the options, the figures, the goals, every window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DaysReport {
    pub days: usize,
    pub seed: u64,
    pub generations: u32,
    pub w_loc: f64,
    pub plan_wall_s: f64,
    pub replan_wall_s: f64,
    pub rate: f64,
    /// Cells the day's cart covers at some step.
    pub changing_cells: usize,
    pub variants: Vec<VariantSummary>,
    pub information_vs_shortest: Option<Paired>,
    pub information_vs_plain: Option<Paired>,
    pub effects: Vec<Effect>,
    pub goals: Vec<Goal>,
    pub results: Vec<DayResult>,
}

/// The options' ranges; the first out of range is refused, naming its field and limit.
fn check(o: &DaysOptions) -> Result<(), DaysError> {
    let invalid = |field, value: &dyn std::fmt::Display, limit: String| {
        Err(DaysError::Invalid {
            field,
            value: value.to_string(),
            limit,
        })
    };
    let max_generations = roam_planner::params::MAX_GENERATIONS;
    if o.days == 0 || o.days > MAX_DAYS {
        return invalid("days", &o.days, format!("1 to {MAX_DAYS} (MAX_DAYS)"));
    }
    if o.generations == 0 || o.generations > max_generations {
        return invalid(
            "generations",
            &o.generations,
            format!("1 to {max_generations}"),
        );
    }
    if !(o.w_loc.is_finite() && o.w_loc >= 0.0) {
        return invalid("w_loc", &o.w_loc, "a finite 0 or more".into());
    }
    if !(o.replan_wall_s.is_finite() && (0.0..=MAX_PLAN_WALL_S).contains(&o.replan_wall_s)) {
        return invalid(
            "replan_wall_s",
            &o.replan_wall_s,
            format!("0 to {MAX_PLAN_WALL_S} seconds"),
        );
    }
    if !(o.plan_wall_s.is_finite() && (0.0..=MAX_PLAN_WALL_S).contains(&o.plan_wall_s)) {
        return invalid(
            "plan_wall_s",
            &o.plan_wall_s,
            format!("0 to {MAX_PLAN_WALL_S} seconds"),
        );
    }
    if !(o.rate.is_finite() && o.rate >= 1.0 && o.rate <= MAX_RATE) {
        return invalid("rate", &o.rate, format!("1 to {MAX_RATE} (MAX_RATE)"));
    }
    if o.variants.is_empty() {
        return invalid("variants", &"empty", "at least one".into());
    }
    if o.jobs == 0 {
        return invalid("jobs", &o.jobs, "at least 1".into());
    }
    Ok(())
}

/// Runs the batch; `progress` after each (variant, day), counted in days.
pub fn run(options: &DaysOptions, progress: Progress<'_>) -> Result<DaysReport, DaysError> {
    check(options)?;
    let world = DayWorld::new(&options.site)?;
    let mut variants = options.variants.clone();
    variants.sort();
    variants.dedup();
    let units: Vec<(Variant, usize)> = (0..options.days)
        .flat_map(|d| variants.iter().map(move |&v| (v, d)))
        .collect();
    let slots = run_in_order(
        &units,
        options.jobs,
        |&(variant, d)| day::run_day(&world, variant, options, d),
        Result::is_err,
        |done, _| progress(Done::of("days", "variant days", done, units.len())),
    );
    let mut results = Vec::with_capacity(units.len());
    for slot in slots {
        match slot {
            Some(r) => results.push(r?),
            None => continue,
        }
    }
    Ok(report(options, &world, results))
}

/// The report of `results`.
pub fn report(options: &DaysOptions, world: &DayWorld, results: Vec<DayResult>) -> DaysReport {
    let summaries: Vec<VariantSummary> = Variant::ALL
        .iter()
        .filter_map(|&v| summary::variant_summary(&results, v))
        .collect();
    let vs_shortest = summary::paired(&results, Variant::Executive, Variant::FastestPath);
    let vs_plain = summary::paired(&results, Variant::Executive, Variant::Plain);
    let effects = [("change", Variant::NoChange), ("peb", Variant::NoPeb)]
        .into_iter()
        .filter_map(|(c, without)| summary::effect(&results, c, without))
        .collect();
    let goals = goals::goals(&summaries, vs_shortest.as_ref(), vs_plain.as_ref());
    DaysReport {
        days: options.days,
        seed: options.seed,
        generations: options.generations,
        w_loc: options.w_loc,
        plan_wall_s: options.plan_wall_s,
        replan_wall_s: options.replan_wall_s,
        rate: options.rate,
        changing_cells: world.changing_cells,
        variants: summaries,
        information_vs_shortest: vs_shortest,
        information_vs_plain: vs_plain,
        effects,
        goals,
        results,
    }
}
