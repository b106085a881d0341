//! `roam reproduce fleet --days N`: a fleet's week in the warehouse, in batch, on the
//! services' own code. Ten robots ([`roam_mission::shift`]'s warehouse shift, repeated
//! N times on one clock) each run the executive's own window machine
//! ([`crate::reproduce::executive`]); their plans are the planner's own answers (or
//! the patrol's, [`patrol`]); the sim, localization and the APF controller step every
//! robot together ([`crate::closed_loop::stepper`]); the fleet's mapper is the mapper's
//! own code fed every robot's observation ([`mapper`]). Objects land in and leave the
//! aisles and the dock at each zone's rate (the scenario's `changes`), and the week is
//! measured by how soon the fleet sees each change ([`events`]) and how well its map
//! of the world now predicts the truth ([`measure`]), per variant ([`variant`]).
//!
//! **Common random numbers.** The sim's seed (and so the objects' schedule, the ranges'
//! noise, the walkers) and each robot's plan seed depend on the batch's seed only,
//! never on the variant; the variants run in parallel (`jobs`) and the report is the
//! same bit for bit whatever the number of threads (the plans' computing times aside:
//! they are this machine's wall clock).

pub mod events;
pub mod goals;
pub mod mapper;
pub mod measure;
pub mod patrol;
pub mod picture;
pub mod seen;
pub mod summary;
pub mod variant;
pub mod week;
pub mod world;

mod error;
mod options;

use std::fmt::Write;

use roam_proto::planner::PlannerModel;
use serde::Serialize;

use crate::parallel::run_in_order;
use crate::progress::{Done, Progress};

pub use error::FleetError;
pub use goals::FleetGoal;
pub use options::FleetOptions;
pub use summary::FleetSummary;
pub use variant::FleetVariant;
pub use world::FleetWorld;

/// The most days (shifts) one batch runs.
pub const MAX_FLEET_DAYS: usize = 365;

/// The batch's report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FleetReport {
    pub days: usize,
    pub seed: u64,
    /// The curious variants' planner.
    pub model: PlannerModel,
    pub generations: u32,
    pub robots: usize,
    pub shift_s: f64,
    pub variants: Vec<FleetSummary>,
    pub goals: Vec<FleetGoal>,
    /// Every variant's windows, map samples and change events.
    pub weeks: Vec<measure::WeekRecord>,
}

fn check(o: &FleetOptions) -> Result<(), FleetError> {
    let invalid = |field, value: &dyn std::fmt::Display, limit: String| {
        Err(FleetError::Invalid {
            field,
            value: value.to_string(),
            limit,
        })
    };
    let max_generations = roam_planner::params::MAX_GENERATIONS;
    if o.days == 0 || o.days > MAX_FLEET_DAYS {
        return invalid(
            "days",
            &o.days,
            format!("1 to {MAX_FLEET_DAYS} (max_fleet_days)"),
        );
    }
    if o.generations == 0 || o.generations > max_generations {
        return invalid(
            "generations",
            &o.generations,
            format!("1 to {max_generations}"),
        );
    }
    if !(o.peb_free_m.is_finite() && o.peb_free_m >= 0.0) {
        return invalid("peb_free_m", &o.peb_free_m, "a finite 0 or more".into());
    }
    if !(o.w_loc.is_finite() && o.w_loc >= 0.0) {
        return invalid("w_loc", &o.w_loc, "a finite 0 or more".into());
    }
    let max_wall = crate::reproduce::mission::days::MAX_PLAN_WALL_S;
    if !(o.plan_wall_s.is_finite() && (0.0..=max_wall).contains(&o.plan_wall_s)) {
        return invalid(
            "plan_wall_s",
            &o.plan_wall_s,
            format!("0 to {max_wall} seconds"),
        );
    }
    let max_rate = crate::reproduce::mission::days::MAX_RATE;
    if !(o.rate.is_finite() && o.rate >= 1.0 && o.rate <= max_rate) {
        return invalid("rate", &o.rate, format!("1 to {max_rate}"));
    }
    if o.variants.is_empty() {
        return invalid("variants", &"empty", "at least one".into());
    }
    if o.jobs == 0 {
        return invalid("jobs", &o.jobs, "at least 1".into());
    }
    Ok(())
}

/// Runs the batch on the built-in warehouse; `progress` after each variant's week.
pub fn run(options: &FleetOptions, progress: Progress<'_>) -> Result<FleetReport, FleetError> {
    check(options)?;
    let world = FleetWorld::warehouse()?;
    run_on(&world, options, progress)
}

/// Runs the batch on `world`.
pub fn run_on(
    world: &FleetWorld,
    options: &FleetOptions,
    progress: Progress<'_>,
) -> Result<FleetReport, FleetError> {
    check(options)?;
    if world.patrol.is_none() && options.variants.contains(&FleetVariant::Patrol) {
        return Err(FleetError::World(
            "the patrol variant needs the operator's loop: give patrol: [[x, y], ...] in the shift file, or leave the variant out (--variants)".into(),
        ));
    }
    let mut variants = options.variants.clone();
    variants.sort();
    variants.dedup();
    let slots = run_in_order(
        &variants,
        options.jobs,
        |&v| week::run_week(world, v, options),
        Result::is_err,
        |done, _| progress(Done::of("week", "variants", done, variants.len())),
    );
    let mut weeks = Vec::with_capacity(variants.len());
    for slot in slots.into_iter().flatten() {
        weeks.push(slot?);
    }
    let shift_s = world.shift.length_s;
    let summaries: Vec<FleetSummary> = weeks
        .iter()
        .map(|w| summary::summarize(w, shift_s, options.days))
        .collect();
    Ok(FleetReport {
        days: options.days,
        seed: options.seed,
        model: options.model,
        generations: options.generations,
        robots: world.shift.robots.len(),
        shift_s,
        goals: goals::goals(&summaries),
        variants: summaries,
        weeks,
    })
}

fn num(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".to_owned(), |v| format!("{v:.digits$}"))
}

fn spread(s: Option<summary::Spread>, digits: usize) -> String {
    s.map_or_else(String::new, |s| {
        format!(" ({:.digits$}–{:.digits$})", s.min, s.max)
    })
}

impl FleetReport {
    /// The report as a table, then the goals.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "roam reproduce fleet: {} robots, {} shifts of {:.0} s, seed {}, curious plans by {} ({} generations for a GA)",
            self.robots, self.days, self.shift_s, self.seed, self.model.as_str(), self.generations
        );
        let _ = writeln!(
            out,
            "| variant | late | share | changes | seen ≤10 min | seen ≤1 h | detection median s (by day) | Brier (by day) | static map's Brier (by day) | Brier zones / others | information / robot-hour (by day) | halted / robot-day | plans | refused plans / scans | p50 / p99 ms | wall s |"
        );
        let _ = writeln!(
            out,
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        );
        for s in &self.variants {
            let _ = writeln!(
                out,
                "| {} | {}/{} | {} | {} | {} | {} | {}{} | {}{} | {}{} | {} / {} | {}{} | {:.1} | {} | {} / {} | {} / {} | {:.0} |",
                s.variant,
                s.late,
                s.windows,
                num(s.share_median, 2),
                s.changes,
                num(s.seen_within_10_min, 2),
                num(s.seen_within_1_h, 2),
                num(s.detection_median_s, 0),
                spread(s.detection_median_by_day, 0),
                num(s.brier, 4),
                spread(s.brier_by_day, 4),
                num(s.brier_static, 4),
                spread(s.brier_static_by_day, 4),
                num(s.brier_zones, 4),
                num(s.brier_others, 4),
                num(s.information_per_robot_hour, 0),
                spread(s.information_per_robot_hour_by_day, 0),
                s.halted_steps_per_robot_day,
                s.curious_plans,
                s.refused_plans
                    .map_or_else(|| "-".to_owned(), |n| n.to_string()),
                s.localization_errors
                    .map_or_else(|| "-".to_owned(), |n| n.to_string()),
                num(s.plan_p50_ms, 0),
                num(s.plan_p99_ms, 0),
                s.wall_s,
            );
        }
        for s in self.variants.iter().filter(|s| !s.refusals.is_empty()) {
            let kinds: Vec<String> = s
                .refusals
                .iter()
                .map(|(kind, n)| format!("{kind} {n}"))
                .collect();
            let _ = writeln!(out, "refused plans of {}: {}", s.variant, kinds.join(", "));
        }
        out.push('\n');
        for g in &self.goals {
            let _ = writeln!(
                out,
                "  {:<50} {:>8} {} {:<6} {}",
                g.goal,
                num(g.figure, 3),
                match g.target {
                    crate::reproduce::mission::days::goals::Target::AtLeast => ">=",
                    crate::reproduce::mission::days::goals::Target::AtMost => "<=",
                },
                g.threshold,
                g.verdict.as_str()
            );
        }
        out
    }
}
