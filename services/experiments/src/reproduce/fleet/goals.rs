//! The fleet's goals, each judged from the figures (the verdict is the comparison of
//! the figure with its threshold, nothing else).

use crate::reproduce::mission::days::goals::{judge, Goal, Target};

use super::summary::FleetSummary;

/// One goal of the fleet's week: the days batch's [`Goal`], judged the same way; the
/// fleet's figures are their own account, so it names no shortfall.
pub type FleetGoal = Goal;

fn goal(goal: &'static str, figure: Option<f64>, target: Target, threshold: f64) -> FleetGoal {
    Goal {
        goal,
        figure,
        target,
        threshold,
        verdict: judge(figure, target, threshold),
        shortfall: None,
    }
}

fn ratio(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    }
}

/// The goals on `summaries`.
pub fn goals(summaries: &[FleetSummary]) -> Vec<FleetGoal> {
    let of = |name: &str| summaries.iter().find(|s| s.variant == name);
    let field = |name: &str, f: fn(&FleetSummary) -> Option<f64>| of(name).and_then(f);
    let latency = |s: &FleetSummary| s.detection_median_s;
    let brier = |s: &FleetSummary| s.brier;
    let info = |s: &FleetSummary| s.information_per_robot_hour;
    vec![
        goal(
            "late windows, most of any variant",
            summaries.iter().map(|s| s.late as f64).reduce(f64::max),
            Target::AtMost,
            0.0,
        ),
        goal(
            "median detection latency, news / patrol",
            ratio(field("news", latency), field("patrol", latency)),
            Target::AtMost,
            0.5,
        ),
        goal(
            "median detection latency, news / independent",
            ratio(field("news", latency), field("independent", latency)),
            Target::AtMost,
            0.7,
        ),
        goal(
            "map error (Brier), news / tasks_only",
            ratio(field("news", brier), field("tasks_only", brier)),
            Target::AtMost,
            0.7,
        ),
        goal(
            "map error (Brier), news / patrol",
            ratio(field("news", brier), field("patrol", brier)),
            Target::AtMost,
            1.0,
        ),
        goal(
            "information per robot-hour, news / independent",
            ratio(field("news", info), field("independent", info)),
            Target::AtLeast,
            1.0,
        ),
    ]
}
