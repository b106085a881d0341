//! The batch's promises: the same options give the same report bit for bit whatever
//! the threads, a day's noise and seeds do not depend on the variant (common random
//! numbers), verdicts come from the figures, and bad options are refused by name.

use std::sync::OnceLock;

use super::day::{day_seed, DayResult};
use super::goals::{goals, Verdict};
use super::measure::WindowResult;
use super::summary::{paired, variant_summary};
use super::*;
use crate::progress::silent;

/// A small batch that stays fast in debug builds: two days, three variants (plain, the
/// executive, the fastest path), a few GA generations.
fn small(jobs: usize) -> DaysOptions {
    DaysOptions {
        days: 2,
        seed: 3,
        generations: 20,
        variants: vec![Variant::Plain, Variant::Executive, Variant::FastestPath],
        jobs,
        ..DaysOptions::default()
    }
}

/// The small batch on one thread, run once for the tests that read it.
fn one_thread() -> &'static DaysReport {
    static REPORT: OnceLock<DaysReport> = OnceLock::new();
    REPORT.get_or_init(|| run(&small(1), &silent).expect("the small batch runs"))
}

/// Everything a report holds, bit for bit: its JSON (floats printed exactly) and the
/// true paths the JSON leaves out.
fn bits(r: &DaysReport) -> (String, Vec<Vec<u64>>) {
    let json = serde_json::to_string(r).expect("the report serializes");
    let truth = r
        .results
        .iter()
        .map(|d| d.truth.iter().flat_map(|p| p.map(f64::to_bits)).collect())
        .collect();
    (json, truth)
}

#[test]
fn the_same_options_give_the_same_report_bit_for_bit_on_one_or_two_threads() {
    let once = one_thread();
    let two = run(&small(2), &silent).expect("runs on two threads");
    assert_eq!(bits(once), bits(&two));
    // Every (variant, day) is in the report, in order, and the day was driven.
    let units: Vec<(usize, Variant)> = once.results.iter().map(|d| (d.day, d.variant)).collect();
    let expected: Vec<(usize, Variant)> = (0..2)
        .flat_map(|d| [Variant::Plain, Variant::Executive, Variant::FastestPath].map(|v| (d, v)))
        .collect();
    assert_eq!(units, expected);
    for d in &once.results {
        assert_eq!(d.windows.len(), 4, "day {} {:?}", d.day, d.variant);
        assert!(d.truth.len() > 100);
    }
}

#[test]
fn a_days_noise_and_seeds_do_not_depend_on_the_variant() {
    let report = one_thread();
    for day in 0..2 {
        let ranges: Vec<&Vec<f64>> = report
            .results
            .iter()
            .filter(|d| d.day == day)
            .map(|d| &d.first_ranges)
            .collect();
        assert_eq!(ranges.len(), 3);
        assert!(!ranges[0].is_empty());
        assert!(
            ranges.iter().all(|r| *r == ranges[0]),
            "day {day}: {ranges:?}"
        );
    }
    let first = |day: usize| {
        &report
            .results
            .iter()
            .find(|d| d.day == day)
            .expect("ran")
            .first_ranges
    };
    assert_ne!(first(0), first(1), "days differ in their noise");
    // The seeds are functions of the batch's seed and the day only: there is no
    // variant to give them.
    assert_eq!(day_seed(3, 1), day_seed(3, 1));
    assert_ne!(day_seed(3, 0), day_seed(3, 1));
    assert_ne!(day_seed(3, 0), day_seed(4, 0));
}

#[test]
fn the_report_has_every_goal_with_a_verdict_computed_from_its_figure() {
    let report = one_thread();
    assert_eq!(report.goals.len(), 6);
    for g in &report.goals {
        if g.goal.starts_with("no_peb") {
            assert_eq!(g.verdict, Verdict::NotMeasured, "no_peb did not run: {g:?}");
            continue;
        }
        assert_ne!(g.verdict, Verdict::NotMeasured, "{g:?}");
        assert_eq!(
            g.verdict,
            goals::judge(g.figure, g.target, g.threshold),
            "{g:?}"
        );
        assert_eq!(g.shortfall.is_some(), g.verdict == Verdict::DoesNotHold);
    }
    let table = table::table(report);
    assert!(table.contains("goals (the shipped executive):"), "{table}");
}

/// A window with the figures a test gives.
pub(super) fn window(i: usize, share: f64, info: f64, late: bool) -> WindowResult {
    WindowResult {
        window: i,
        task: format!("t{i}"),
        began_s: 0.0,
        task_start_s: 100.0,
        window_s: 100.0,
        arrival_s: (!late).then_some(100.0 * share),
        late,
        driving_s: 100.0 * share,
        share,
        waited_for_plan_s: 1.0,
        held_s: 0.0,
        holds: 0,
        recoveries: 0,
        late_probability: Some(1e-3),
        early_s: (!late).then_some(100.0 - 100.0 * share),
        budget_s: 99.0,
        curious: true,
        first_plan_cells: 10,
        ga_plans: 1,
        refused_plans: 0,
        driven_information: info,
        planned_information: info * 1.25,
        shortest_information: 1.0,
        driven_over_planned: Some(0.8),
        changing_cells_seen: 2.0,
        peb_mean_m: Some(0.1),
        halted_steps: 0,
        estimate_rms_m: Some(0.05),
        replans: vec!["slack"],
        time_model: None,
    }
}

/// A day of two windows, the second late or not.
pub(super) fn day(variant: Variant, day: usize, info: f64, late: bool) -> DayResult {
    DayResult {
        day,
        variant,
        windows: vec![window(0, 0.5, info, false), window(1, 0.9, info, late)],
        localization_errors: 0,
        first_ranges: Vec::new(),
        reports: Vec::new(),
        truth: Vec::new(),
        asked: Vec::new(),
    }
}

fn judged(results: &[DayResult]) -> Vec<(&'static str, Verdict)> {
    let summaries: Vec<_> = Variant::ALL
        .iter()
        .filter_map(|&v| variant_summary(results, v))
        .collect();
    let vs_shortest = paired(results, Variant::Executive, Variant::FastestPath);
    let vs_plain = paired(results, Variant::Executive, Variant::Plain);
    goals(&summaries, vs_shortest.as_ref(), vs_plain.as_ref())
        .into_iter()
        .map(|g| (g.goal, g.verdict))
        .collect()
}

#[test]
fn synthetic_figures_short_of_every_goal_do_not_hold_and_good_ones_hold() {
    // Share 0.7, a late window, driven/planned 0.8, +10% on the fastest path and plain,
    // no_peb halted 100 steps a day.
    let mut held = day(Variant::NoPeb, 0, 100.0, false);
    held.windows[0].halted_steps = 100;
    let poor = [
        day(Variant::Executive, 0, 110.0, true),
        day(Variant::FastestPath, 0, 100.0, false),
        day(Variant::Plain, 0, 100.0, false),
        held,
    ];
    let verdicts = judged(&poor);
    assert_eq!(verdicts.len(), 6);
    assert!(
        verdicts.iter().all(|(_, v)| *v == Verdict::DoesNotHold),
        "{verdicts:?}"
    );
    // Share 0.95, none late, driven/planned 0.97, +100% and +50%.
    let mut new = day(Variant::Executive, 0, 300.0, false);
    for w in &mut new.windows {
        w.share = 0.95;
        w.driven_over_planned = Some(0.97);
    }
    let good = [
        new,
        day(Variant::FastestPath, 0, 150.0, false),
        day(Variant::Plain, 0, 200.0, false),
        day(Variant::NoPeb, 0, 200.0, false),
    ];
    let verdicts = judged(&good);
    assert!(
        verdicts.iter().all(|(_, v)| *v == Verdict::Holds),
        "{verdicts:?}"
    );
    // The same good day without the baselines: those three goals are not measured.
    let verdicts = judged(&good[..1]);
    assert_eq!(
        verdicts
            .iter()
            .filter(|(_, v)| *v == Verdict::NotMeasured)
            .count(),
        3,
        "{verdicts:?}"
    );
}

#[test]
fn bad_options_are_refused_naming_the_field_and_its_limit() {
    let refused = |options: DaysOptions| match run(&options, &silent) {
        Err(DaysError::Invalid { field, limit, .. }) => (field, limit),
        other => panic!("not refused: {other:?}"),
    };
    let ok = small(1);
    let (field, limit) = refused(DaysOptions {
        days: 0,
        ..ok.clone()
    });
    assert_eq!(field, "days");
    assert!(limit.contains(&MAX_DAYS.to_string()), "{limit}");
    assert_eq!(
        refused(DaysOptions {
            days: MAX_DAYS + 1,
            ..ok.clone()
        })
        .0,
        "days"
    );
    for cost in [-1.0, f64::NAN, f64::INFINITY, MAX_PLAN_WALL_S + 1.0] {
        let (field, limit) = refused(DaysOptions {
            plan_wall_s: cost,
            ..ok.clone()
        });
        assert_eq!(field, "plan_wall_s", "{cost}");
        assert!(limit.contains("seconds"), "{limit}");
    }
    for rate in [0.5, f64::NAN, MAX_RATE * 2.0] {
        assert_eq!(refused(DaysOptions { rate, ..ok.clone() }).0, "rate");
    }
    assert_eq!(
        refused(DaysOptions {
            generations: 0,
            ..ok.clone()
        })
        .0,
        "generations"
    );
    assert_eq!(
        refused(DaysOptions {
            w_loc: f64::NAN,
            ..ok.clone()
        })
        .0,
        "w_loc"
    );
    assert_eq!(
        refused(DaysOptions {
            variants: Vec::new(),
            ..ok.clone()
        })
        .0,
        "variants"
    );
    assert_eq!(refused(DaysOptions { jobs: 0, ..ok }).0, "jobs");
    let message = DaysError::Invalid {
        field: "days",
        value: "0".into(),
        limit: "1 to 10000 (MAX_DAYS)".into(),
    }
    .to_string();
    assert_eq!(message, "days is 0; give 1 to 10000 (MAX_DAYS)");
}
