//! The batch's figures per variant and per window of the day, the paired comparisons
//! between variants (the same days, the same noise), and each coupling's effect alone.

use std::collections::BTreeMap;

use serde::Serialize;

use super::day::DayResult;
use super::measure::WindowResult;
use super::stats::{gain, mean, median};
use super::variant::Variant;

/// One variant over the days.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VariantSummary {
    pub variant: Variant,
    pub days: usize,
    pub windows: usize,
    /// The median over every window of the share driven.
    pub share_median: Option<f64>,
    /// Windows that arrived after the task's start, or never.
    pub late: usize,
    /// The median over the windows whose plans promised any.
    pub driven_over_planned_median: Option<f64>,
    /// Per day (summed over its windows), the median over days.
    pub information_per_day_median: Option<f64>,
    pub planned_information_per_day_median: Option<f64>,
    pub changing_cells_per_day_median: Option<f64>,
    pub halted_steps_per_day_median: Option<f64>,
    /// The mean over windows of their mean PEB at the true positions, metres.
    pub peb_mean_m: Option<f64>,
    /// The median over windows of the estimates' RMS error, metres.
    pub estimate_rms_median_m: Option<f64>,
    pub replans_per_day: Option<f64>,
    pub replans_by_reason: BTreeMap<&'static str, usize>,
    pub ga_plans_per_day: Option<f64>,
    /// Plans the planner refused and scans localization refused, over every day: 0 on
    /// a healthy run, counted so that an error cannot hide as a fallback.
    pub refused_plans: u64,
    pub localization_errors: u64,
    /// Windows whose first plan was curious.
    pub curious_windows: usize,
    /// The median over arrived windows of the time model's relative error.
    pub model_error_median: Option<f64>,
    pub by_window: Vec<WindowBreakdown>,
}

/// One window of the day (its index), over the days.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WindowBreakdown {
    pub window: usize,
    pub task: String,
    pub days: usize,
    pub window_s_median: Option<f64>,
    pub share_median: Option<f64>,
    pub driving_s_median: Option<f64>,
    pub waited_for_plan_s_median: Option<f64>,
    pub held_s_median: Option<f64>,
    /// Over the windows that arrived on time.
    pub early_s_median: Option<f64>,
    pub late: usize,
    /// Late windows that never arrived.
    pub never_arrived: usize,
    /// Late windows in which the controller held the robot for its PEB.
    pub late_halted: usize,
    /// Over the windows that arrived late: by how much (arrival − task start), seconds.
    pub late_by_s_median: Option<f64>,
    pub late_by_s_max: Option<f64>,
    /// Over the windows that arrived late: the time model's relative error on the drive
    /// (negative: it promised a faster drive than the robot made).
    pub late_model_error_median: Option<f64>,
    pub driven_over_planned_median: Option<f64>,
    pub driven_information_median: Option<f64>,
    pub planned_information_median: Option<f64>,
    pub shortest_information_median: Option<f64>,
    pub curious: usize,
    pub first_plan_cells_median: Option<f64>,
    pub replans_median: Option<f64>,
    pub v_lin_median: Option<f64>,
    pub v_ang_median: Option<f64>,
    pub model_error_median: Option<f64>,
}

/// A variant's driven information against another's, day by day.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Paired {
    pub of: Variant,
    pub against: Variant,
    pub days: usize,
    /// The median over days of (the day's information / the other's − 1).
    pub median_gain: Option<f64>,
    /// Over all days: Σ information / Σ the other's − 1.
    pub total_gain: Option<f64>,
}

/// One coupling's effect alone: `new` against `new` without it, on the same days.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Effect {
    pub coupling: &'static str,
    pub with: Variant,
    pub without: Variant,
    pub figures: Vec<EffectFigure>,
}

/// One figure of an effect: per day (or per window for the means), with and without,
/// and the median over days of the paired difference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectFigure {
    pub figure: &'static str,
    pub with: Option<f64>,
    pub without: Option<f64>,
    pub paired_median_difference: Option<f64>,
}

fn windows<'a, 'b>(days: &'b [&'a DayResult]) -> impl Iterator<Item = &'a WindowResult> + 'b
where
    'a: 'b,
{
    days.iter().flat_map(|d| d.windows.iter())
}

/// The days of `variant`, by day.
pub fn days_of(results: &[DayResult], variant: Variant) -> Vec<&DayResult> {
    let mut days: Vec<&DayResult> = results.iter().filter(|d| d.variant == variant).collect();
    days.sort_by_key(|d| d.day);
    days
}

fn per_day(days: &[&DayResult], f: impl Fn(&WindowResult) -> f64) -> Vec<f64> {
    days.iter()
        .map(|d| d.windows.iter().map(&f).sum())
        .collect()
}

/// A variant's figures; `None` when it did not run.
pub fn variant_summary(results: &[DayResult], variant: Variant) -> Option<VariantSummary> {
    let days = days_of(results, variant);
    if days.is_empty() {
        return None;
    }
    let all: Vec<&WindowResult> = windows(&days).collect();
    let mut by_reason = BTreeMap::new();
    for w in &all {
        for r in &w.replans {
            *by_reason.entry(*r).or_insert(0) += 1;
        }
    }
    let n_windows = days.iter().map(|d| d.windows.len()).max().unwrap_or(0);
    let by_window = (0..n_windows)
        .filter_map(|i| {
            let ws: Vec<&WindowResult> = all.iter().copied().filter(|w| w.window == i).collect();
            breakdown(i, &ws)
        })
        .collect();
    Some(VariantSummary {
        variant,
        days: days.len(),
        windows: all.len(),
        share_median: median(all.iter().map(|w| w.share)),
        late: all.iter().filter(|w| w.late).count(),
        driven_over_planned_median: median(all.iter().filter_map(|w| w.driven_over_planned)),
        information_per_day_median: median(per_day(&days, |w| w.driven_information)),
        planned_information_per_day_median: median(per_day(&days, |w| w.planned_information)),
        changing_cells_per_day_median: median(per_day(&days, |w| w.changing_cells_seen)),
        halted_steps_per_day_median: median(per_day(&days, |w| w.halted_steps as f64)),
        peb_mean_m: mean(all.iter().filter_map(|w| w.peb_mean_m)),
        estimate_rms_median_m: median(all.iter().filter_map(|w| w.estimate_rms_m)),
        replans_per_day: mean(per_day(&days, |w| w.replans.len() as f64)),
        replans_by_reason: by_reason,
        ga_plans_per_day: mean(per_day(&days, |w| f64::from(w.ga_plans))),
        refused_plans: days
            .iter()
            .flat_map(|d| &d.windows)
            .map(|w| u64::from(w.refused_plans))
            .sum(),
        localization_errors: days.iter().map(|d| d.localization_errors).sum(),
        curious_windows: all.iter().filter(|w| w.curious).count(),
        model_error_median: median(all.iter().filter_map(|w| w.time_model.map(|m| m.error))),
        by_window,
    })
}

fn breakdown(window: usize, ws: &[&WindowResult]) -> Option<WindowBreakdown> {
    let first = ws.first()?;
    let late: Vec<&&WindowResult> = ws.iter().filter(|w| w.late).collect();
    let late_by: Vec<f64> = late
        .iter()
        .filter_map(|w| w.arrival_s.map(|a| a - w.task_start_s))
        .collect();
    let model = |f: fn(&super::measure::TimeModelUse) -> f64| {
        median(ws.iter().filter_map(|w| w.time_model.as_ref().map(f)))
    };
    Some(WindowBreakdown {
        window,
        task: first.task.clone(),
        days: ws.len(),
        window_s_median: median(ws.iter().map(|w| w.window_s)),
        share_median: median(ws.iter().map(|w| w.share)),
        driving_s_median: median(ws.iter().map(|w| w.driving_s)),
        waited_for_plan_s_median: median(ws.iter().map(|w| w.waited_for_plan_s)),
        held_s_median: median(ws.iter().map(|w| w.held_s)),
        early_s_median: median(ws.iter().filter_map(|w| w.early_s)),
        late: late.len(),
        never_arrived: late.iter().filter(|w| w.arrival_s.is_none()).count(),
        late_halted: late.iter().filter(|w| w.halted_steps > 0).count(),
        late_by_s_median: median(late_by.iter().copied()),
        late_by_s_max: late_by.iter().copied().reduce(f64::max),
        late_model_error_median: median(
            late.iter()
                .filter_map(|w| w.time_model.as_ref().map(|m| m.error)),
        ),
        driven_over_planned_median: median(ws.iter().filter_map(|w| w.driven_over_planned)),
        driven_information_median: median(ws.iter().map(|w| w.driven_information)),
        planned_information_median: median(ws.iter().map(|w| w.planned_information)),
        shortest_information_median: median(ws.iter().map(|w| w.shortest_information)),
        curious: ws.iter().filter(|w| w.curious).count(),
        first_plan_cells_median: median(ws.iter().map(|w| w.first_plan_cells as f64)),
        replans_median: median(ws.iter().map(|w| w.replans.len() as f64)),
        v_lin_median: model(|m| m.v_lin),
        v_ang_median: model(|m| m.v_ang),
        model_error_median: model(|m| m.error),
    })
}

/// Pairs the days two variants both ran.
fn pairs(results: &[DayResult], of: Variant, against: Variant) -> Vec<(&DayResult, &DayResult)> {
    let others = days_of(results, against);
    days_of(results, of)
        .into_iter()
        .filter_map(|a| others.iter().find(|b| b.day == a.day).map(|b| (a, *b)))
        .collect()
}

fn day_sum(d: &DayResult, f: impl Fn(&WindowResult) -> f64) -> f64 {
    d.windows.iter().map(f).sum()
}

/// `of`'s driven information against `against`'s, day by day; `None` when they share
/// no day.
pub fn paired(results: &[DayResult], of: Variant, against: Variant) -> Option<Paired> {
    let days = pairs(results, of, against);
    if days.is_empty() {
        return None;
    }
    let info = |d: &DayResult| day_sum(d, |w| w.driven_information);
    let of_total: f64 = days.iter().map(|(a, _)| info(a)).sum();
    let against_total: f64 = days.iter().map(|(_, b)| info(b)).sum();
    Some(Paired {
        of,
        against,
        days: days.len(),
        median_gain: median(days.iter().filter_map(|(a, b)| gain(info(a), info(b)))),
        total_gain: gain(of_total, against_total),
    })
}

/// A coupling's effect: `new` against `without`.
pub fn effect(results: &[DayResult], coupling: &'static str, without: Variant) -> Option<Effect> {
    let days = pairs(results, Variant::Executive, without);
    if days.is_empty() {
        return None;
    }
    type Pick = fn(&WindowResult) -> f64;
    let sums: [(&'static str, Pick); 4] = [
        ("changing cells seen per day", |w| w.changing_cells_seen),
        ("information per day", |w| w.driven_information),
        ("halted steps per day", |w| w.halted_steps as f64),
        ("late windows per day", |w| f64::from(u8::from(w.late))),
    ];
    let mut figures: Vec<EffectFigure> = sums
        .iter()
        .map(|&(figure, f)| EffectFigure {
            figure,
            with: median(days.iter().map(|(a, _)| day_sum(a, f))),
            without: median(days.iter().map(|(_, b)| day_sum(b, f))),
            paired_median_difference: median(
                days.iter().map(|(a, b)| day_sum(a, f) - day_sum(b, f)),
            ),
        })
        .collect();
    type Mean = fn(&WindowResult) -> Option<f64>;
    let means: [(&'static str, Mean); 2] = [
        ("mean PEB along the drive, m", |w| w.peb_mean_m),
        ("estimate RMS error, m", |w| w.estimate_rms_m),
    ];
    for (figure, f) in means {
        let day_mean = |d: &DayResult| mean(d.windows.iter().filter_map(f));
        figures.push(EffectFigure {
            figure,
            with: median(days.iter().filter_map(|(a, _)| day_mean(a))),
            without: median(days.iter().filter_map(|(_, b)| day_mean(b))),
            paired_median_difference: median(
                days.iter()
                    .filter_map(|(a, b)| Some(day_mean(a)? - day_mean(b)?)),
            ),
        });
    }
    Some(Effect {
        coupling,
        with: Variant::Executive,
        without,
        figures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reproduce::mission::days::tests::day;

    #[test]
    fn figures_come_from_the_windows_and_pairs_from_the_same_days() {
        let results = vec![
            day(Variant::Executive, 0, 200.0, false),
            day(Variant::Executive, 1, 300.0, true),
            day(Variant::FastestPath, 0, 100.0, false),
            day(Variant::FastestPath, 1, 100.0, false),
            // A day only one of them ran is not paired.
            day(Variant::FastestPath, 2, 1.0, false),
        ];
        let new = variant_summary(&results, Variant::Executive).expect("ran");
        assert_eq!((new.days, new.windows, new.late), (2, 4, 1));
        assert_eq!(new.share_median, Some(0.7));
        assert_eq!(new.information_per_day_median, Some(500.0));
        assert_eq!(new.replans_by_reason.get("slack"), Some(&4));
        assert_eq!(new.by_window.len(), 2);
        assert_eq!(new.by_window[1].late, 1);
        assert_eq!(new.by_window[1].never_arrived, 1);
        assert!(variant_summary(&results, Variant::Plain).is_none());
        let p = paired(&results, Variant::Executive, Variant::FastestPath).expect("paired");
        assert_eq!(p.days, 2);
        // Day 0: 400 / 200 − 1 = 1; day 1: 600 / 200 − 1 = 2.
        assert_eq!(p.median_gain, Some(1.5));
        assert_eq!(p.total_gain, Some(1.5));
        assert!(paired(&results, Variant::Executive, Variant::Plain).is_none());
    }
}
