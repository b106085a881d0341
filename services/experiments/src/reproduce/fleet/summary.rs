//! One variant's week in figures, and each figure's spread over the days.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::reproduce::mission::days::stats::{mean, median};

use super::measure::{MapSample, WeekRecord};

/// Detection within this long counts as "soon", seconds: ten minutes, and an hour.
pub const SOON_S: [f64; 2] = [600.0, 3600.0];

/// A figure's spread over the days: its lowest and highest day.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    pub min: f64,
    pub max: f64,
}

impl Spread {
    fn of(values: impl IntoIterator<Item = f64>) -> Option<Spread> {
        values
            .into_iter()
            .filter(|v| v.is_finite())
            .fold(None, |s: Option<Spread>, v| {
                Some(s.map_or(Spread { min: v, max: v }, |s| Spread {
                    min: s.min.min(v),
                    max: s.max.max(v),
                }))
            })
    }
}

/// One variant's figures (module doc).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FleetSummary {
    pub variant: &'static str,
    pub windows: usize,
    pub late: usize,
    pub share_median: Option<f64>,
    pub changes: usize,
    /// The share of changes seen within [`SOON_S`].
    pub seen_within_10_min: Option<f64>,
    pub seen_within_1_h: Option<f64>,
    /// The median time from a change to its sighting, seconds, changes never seen
    /// counted as never (so `None` when more than half were never seen).
    pub detection_median_s: Option<f64>,
    pub detection_median_by_day: Option<Spread>,
    /// The mean Brier score of the map now over the scored cells (all, the cells
    /// objects can cover, the others).
    pub brier: Option<f64>,
    pub brier_zones: Option<f64>,
    pub brier_others: Option<f64>,
    pub brier_by_day: Option<Spread>,
    /// The static map's mean Brier score over the same samples ([`MapSample::static_map`]):
    /// below it, the fleet's belief knows more than a map that never looks.
    pub brier_static: Option<f64>,
    pub brier_static_by_day: Option<Spread>,
    pub information_per_robot_hour: Option<f64>,
    pub information_per_robot_hour_by_day: Option<Spread>,
    pub halted_steps_per_robot_day: f64,
    pub curious_plans: usize,
    /// Plans the planner refused (errors, not budget cuts), over the windows that say;
    /// scans localization refused (`None`: not counted, live). Both 0 on a healthy run:
    /// they are counted so that a planner or localization error cannot hide as a
    /// fallback.
    pub refused_plans: Option<u64>,
    /// The refused plans by kind (`roam_planner::plan::PlanError::kind`), so a storm of
    /// one kind shows what it is.
    pub refusals: BTreeMap<&'static str, u64>,
    pub localization_errors: Option<u64>,
    /// Curious plans per second of the planner's computing, and their latency.
    pub plans_per_s: Option<f64>,
    pub plan_p50_ms: Option<f64>,
    pub plan_p99_ms: Option<f64>,
    pub wall_s: f64,
}

/// The median with never-seen changes as +∞ (module doc of the field).
fn censored_median(latencies: &[Option<f64>]) -> Option<f64> {
    let mut v: Vec<f64> = latencies
        .iter()
        .map(|l| l.unwrap_or(f64::INFINITY))
        .collect();
    v.sort_by(f64::total_cmp);
    let m = match v.len() {
        0 => return None,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    };
    m.is_finite().then_some(m)
}

fn quantile(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let i = ((sorted.len() as f64 - 1.0) * q).round() as usize;
    sorted.get(i).copied()
}

/// The figures of `week`, whose shifts are `shift_s` long and days `days`.
pub fn summarize(week: &WeekRecord, shift_s: f64, days: usize) -> FleetSummary {
    // The last shift runs until its last window ends, past `days × shift_s` (a live
    // run's `--shift-s` is where its tasks stop starting): what comes after counts in
    // it, so the by-day figures cover every sample and change.
    let last_day = days.saturating_sub(1);
    let day_of = |t: f64| ((t / shift_s).floor().max(0.0) as usize).min(last_day);
    let latencies: Vec<Option<f64>> = week.events.iter().map(|e| e.latency_s()).collect();
    let within = |s: f64| {
        (!latencies.is_empty()).then(|| {
            latencies
                .iter()
                .filter(|l| l.is_some_and(|l| l <= s))
                .count() as f64
                / latencies.len() as f64
        })
    };
    let by_day = |d: usize| -> Vec<Option<f64>> {
        week.events
            .iter()
            .filter(|e| day_of(e.at_s) == d)
            .map(|e| e.latency_s())
            .collect()
    };
    let hours = week.robots as f64 * (shift_s / 3600.0);
    let info_day = |d: usize| {
        week.windows
            .iter()
            .filter(|w| w.day == d)
            .map(|w| w.driven_information)
            .sum::<f64>()
            / hours
    };
    let brier_day = |d: usize, of: fn(&MapSample) -> f64| {
        mean(
            week.maps
                .iter()
                .filter(|m| day_of(m.t_s - 1e-9) == d)
                .map(of),
        )
    };
    let mut lat = week.plan_latencies_s.clone();
    lat.sort_by(f64::total_cmp);
    let plan_s: f64 = lat.iter().sum();
    let info_total: f64 = week.windows.iter().map(|w| w.driven_information).sum();
    FleetSummary {
        variant: week.variant.name(),
        windows: week.windows.len(),
        late: week.windows.iter().filter(|w| w.late).count(),
        share_median: median(week.windows.iter().map(|w| w.share)),
        changes: week.events.len(),
        seen_within_10_min: within(SOON_S[0]),
        seen_within_1_h: within(SOON_S[1]),
        detection_median_s: censored_median(&latencies),
        detection_median_by_day: Spread::of((0..days).filter_map(|d| censored_median(&by_day(d)))),
        brier: mean(week.maps.iter().map(|m| m.all)),
        brier_zones: mean(week.maps.iter().map(|m| m.zones)),
        brier_others: mean(week.maps.iter().map(|m| m.others)),
        brier_by_day: Spread::of((0..days).filter_map(|d| brier_day(d, |m| m.all))),
        brier_static: mean(week.maps.iter().map(|m| m.static_map)),
        brier_static_by_day: Spread::of((0..days).filter_map(|d| brier_day(d, |m| m.static_map))),
        information_per_robot_hour: (hours > 0.0 && days > 0)
            .then(|| info_total / (hours * days as f64)),
        information_per_robot_hour_by_day: Spread::of((0..days).map(info_day)),
        halted_steps_per_robot_day: week.halted_steps.iter().sum::<u64>() as f64
            / (week.robots.max(1) * days.max(1)) as f64,
        curious_plans: lat.len(),
        refused_plans: week
            .windows
            .iter()
            .filter_map(|w| w.refused_plans)
            .map(u64::from)
            .reduce(|a, b| a + b),
        refusals: week.windows.iter().flat_map(|w| &w.refusals).fold(
            BTreeMap::new(),
            |mut all, (&kind, &n)| {
                *all.entry(kind).or_default() += u64::from(n);
                all
            },
        ),
        localization_errors: week.localization_errors,
        plans_per_s: (plan_s > 0.0).then(|| lat.len() as f64 / plan_s),
        plan_p50_ms: quantile(&lat, 0.5).map(|s| s * 1e3),
        plan_p99_ms: quantile(&lat, 0.99).map(|s| s * 1e3),
        wall_s: week.wall_s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn never_seen_changes_count_as_never_in_the_median() {
        assert_eq!(censored_median(&[Some(1.0), Some(3.0), None]), Some(3.0));
        assert_eq!(censored_median(&[Some(1.0), None, None]), None);
        assert_eq!(censored_median(&[]), None);
        assert_eq!(quantile(&[1.0, 2.0, 3.0], 0.5), Some(2.0));
        assert_eq!(
            Spread::of([3.0, f64::NAN, 1.0]),
            Some(Spread { min: 1.0, max: 3.0 })
        );
    }

    #[test]
    fn refused_plans_are_summed_by_kind_over_the_windows_that_count_them() {
        use crate::reproduce::fleet::measure::WindowRecord;
        use crate::reproduce::fleet::variant::FleetVariant;
        let window = |refusals: &[(&'static str, u32)]| WindowRecord {
            robot: 0,
            day: 0,
            task: "pick".into(),
            window_s: 60.0,
            late: false,
            share: 0.5,
            driven_information: 0.0,
            ga_plans: 1,
            refused_plans: Some(refusals.iter().map(|r| r.1).sum()),
            refusals: refusals.iter().copied().collect(),
        };
        let mut week = WeekRecord::new(FleetVariant::News, 1);
        week.windows = vec![
            window(&[("goal_blocked", 3), ("no_path", 1)]),
            window(&[]),
            window(&[("goal_blocked", 2)]),
        ];
        let s = summarize(&week, 3600.0, 1);
        assert_eq!(s.refused_plans, Some(6));
        assert_eq!(
            s.refusals.into_iter().collect::<Vec<_>>(),
            vec![("goal_blocked", 5), ("no_path", 1)]
        );
    }

    #[test]
    fn what_comes_after_the_last_shift_counts_in_it() {
        let mut week = WeekRecord::new(crate::reproduce::fleet::variant::FleetVariant::News, 1);
        let sample = |t_s: f64, all: f64| MapSample {
            t_s,
            zones: all,
            others: all,
            all,
            static_map: all,
        };
        // One shift of 900 s, the last sample at 960 s (the last window ran on).
        week.maps = vec![sample(60.0, 0.01), sample(900.0, 0.02), sample(960.0, 0.03)];
        let s = summarize(&week, 900.0, 1);
        let by_day = s.brier_by_day.expect("a day");
        assert!(
            (by_day.min - 0.02).abs() < 1e-12 && by_day.max == by_day.min,
            "{by_day:?}"
        );
        assert!((s.brier.expect("scored") - 0.02).abs() < 1e-12);
    }
}
