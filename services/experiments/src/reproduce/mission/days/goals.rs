//! The goals for the shipped executive, each judged from the
//! figures, and what falls short explained by the figures that account for it.

use std::fmt::Write;

use serde::Serialize;

use super::summary::{Paired, VariantSummary, WindowBreakdown};
use super::variant::Variant;

/// How a figure is held against its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    AtLeast,
    AtMost,
}

/// A goal's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Holds,
    DoesNotHold,
    /// The variants the figure needs did not run.
    NotMeasured,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Holds => "holds",
            Verdict::DoesNotHold => "does not hold",
            Verdict::NotMeasured => "not measured",
        }
    }
}

/// One goal and how the new executive did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Goal {
    pub goal: &'static str,
    pub figure: Option<f64>,
    pub target: Target,
    pub threshold: f64,
    pub verdict: Verdict,
    /// When it does not hold: the figures that account for it.
    pub shortfall: Option<String>,
}

/// The verdict is the comparison of the figure with the threshold, nothing else.
pub fn judge(figure: Option<f64>, target: Target, threshold: f64) -> Verdict {
    match figure {
        None => Verdict::NotMeasured,
        Some(f) => {
            let met = match target {
                Target::AtLeast => f >= threshold,
                Target::AtMost => f <= threshold,
            };
            if met {
                Verdict::Holds
            } else {
                Verdict::DoesNotHold
            }
        }
    }
}

/// `x` with `digits`, or `-`.
fn num(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".to_owned(), |v| format!("{v:.digits$}"))
}

fn pct(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_owned(), |v| format!("{:+.0}%", v * 100.0))
}

/// Where a window's time went, from its medians.
fn time_of(w: &WindowBreakdown) -> String {
    format!(
        "w{} {} ({} s): share {}, waited {} s for its plan, held {} s by the PEB guard, early {} s at the task; planned with v_lin {} s/m, v_ang {} s/rad, which predicted {} of the drive; curious first plan in {}/{} days ({} cells)",
        w.window,
        w.task,
        num(w.window_s_median, 0),
        num(w.share_median, 2),
        num(w.waited_for_plan_s_median, 1),
        num(w.held_s_median, 1),
        num(w.early_s_median, 1),
        num(w.v_lin_median, 2),
        num(w.v_ang_median, 2),
        pct(w.model_error_median),
        w.curious,
        w.days,
        num(w.first_plan_cells_median, 0),
    )
}

fn lowest(
    new: &VariantSummary,
    f: impl Fn(&WindowBreakdown) -> Option<f64>,
) -> Option<&WindowBreakdown> {
    new.by_window
        .iter()
        .filter(|w| f(w).is_some())
        .min_by(|a, b| f(a).unwrap_or(0.0).total_cmp(&f(b).unwrap_or(0.0)))
}

fn share_shortfall(new: &VariantSummary, plain: Option<&VariantSummary>) -> String {
    let mut s = format!("median share {}", num(new.share_median, 2));
    if let Some(t) = plain {
        let _ = write!(s, " (plain {})", num(t.share_median, 2));
    }
    s.push_str("; by window: ");
    let parts: Vec<String> = new.by_window.iter().map(time_of).collect();
    s.push_str(&parts.join("; "));
    if let Some(w) = lowest(new, |w| w.share_median) {
        let _ = write!(s, ". The lowest is w{} ({})", w.window, w.task);
    }
    s
}

fn late_shortfall(new: &VariantSummary) -> String {
    let mut s = format!("{} of {} windows late", new.late, new.windows);
    let parts: Vec<String> = new
        .by_window
        .iter()
        .filter(|w| w.late > 0)
        .map(|w| {
            format!(
                "w{} {}: {} late ({} never arrived, {} held for their PEB on the way; the others by median {} s, at most {} s, their time model's error {})",
                w.window,
                w.task,
                w.late,
                w.never_arrived,
                w.late_halted,
                num(w.late_by_s_median, 1),
                num(w.late_by_s_max, 1),
                pct(w.late_model_error_median)
            )
        })
        .collect();
    if !parts.is_empty() {
        let _ = write!(s, ": {}", parts.join("; "));
    }
    let reasons: Vec<String> = new
        .replans_by_reason
        .iter()
        .map(|(r, n)| format!("{r} {n}"))
        .collect();
    let _ = write!(s, "; replans over all days: {}", reasons.join(", "));
    s
}

fn ratio_shortfall(new: &VariantSummary) -> String {
    let parts: Vec<String> = new
        .by_window
        .iter()
        .map(|w| {
            format!(
                "w{} {}: {} (driven {} of planned {})",
                w.window,
                w.task,
                num(w.driven_over_planned_median, 2),
                num(w.driven_information_median, 0),
                num(w.planned_information_median, 0)
            )
        })
        .collect();
    format!(
        "median driven/planned {}; by window: {}",
        num(new.driven_over_planned_median, 3),
        parts.join("; ")
    )
}

fn information_shortfall(new: &VariantSummary, other: &VariantSummary, p: &Paired) -> String {
    let parts: Vec<String> = new
        .by_window
        .iter()
        .zip(&other.by_window)
        .map(|(a, b)| {
            format!(
                "w{} {}: {} against {} (planned {} against {}; curious first plan in {}/{} days)",
                a.window,
                a.task,
                num(a.driven_information_median, 0),
                num(b.driven_information_median, 0),
                num(a.planned_information_median, 0),
                num(b.planned_information_median, 0),
                a.curious,
                a.days
            )
        })
        .collect();
    format!(
        "executive {} per day against {} {} (median of the days' gains {}, all days {}); by window, median driven information: {}",
        num(new.information_per_day_median, 0),
        other.variant.name(),
        num(other.information_per_day_median, 0),
        pct(p.median_gain),
        pct(p.total_gain),
        parts.join("; ")
    )
}

/// The halted steps of a day whose robot the PEB guard holds in the north-east room for
/// the rest of the day: `no_peb` with `recover: false` (762 a day over 50 days).
pub const HALTED_STEPS_BEFORE_RECOVERY: f64 = 762.0;

/// The share of [`HALTED_STEPS_BEFORE_RECOVERY`] a day of `no_peb` may keep.
pub const HALTED_STEPS_SHARE: f64 = 0.05;

fn halted_shortfall(no_peb: &VariantSummary) -> String {
    let parts: Vec<String> = no_peb
        .by_window
        .iter()
        .map(|w| {
            format!(
                "w{} {}: held by median {} s, {} late ones held",
                w.window,
                w.task,
                num(w.held_s_median, 1),
                w.late_halted
            )
        })
        .collect();
    format!(
        "no_peb halted {} steps a day (median); {}",
        num(no_peb.halted_steps_per_day_median, 0),
        parts.join("; ")
    )
}

/// The goals, judged on the shipped executive (the holds on
/// `no_peb`, where the PEB cost does not keep the robot out of poor coverage).
pub fn goals(
    summaries: &[VariantSummary],
    vs_shortest: Option<&Paired>,
    vs_plain: Option<&Paired>,
) -> Vec<Goal> {
    let of = |v: Variant| summaries.iter().find(|s| s.variant == v);
    let new = of(Variant::Executive);
    let no_peb = of(Variant::NoPeb);
    let mut out = Vec::new();
    let mut goal = |goal, figure, target, threshold, why: &dyn Fn() -> Option<String>| {
        let verdict = judge(figure, target, threshold);
        out.push(Goal {
            goal,
            figure,
            target,
            threshold,
            verdict,
            shortfall: (verdict == Verdict::DoesNotHold).then(why).flatten(),
        });
    };
    goal(
        "median share of each window driven",
        new.and_then(|n| n.share_median),
        Target::AtLeast,
        0.90,
        &|| new.map(|n| share_shortfall(n, of(Variant::Plain))),
    );
    goal(
        "late arrivals",
        new.map(|n| n.late as f64),
        Target::AtMost,
        0.0,
        &|| new.map(late_shortfall),
    );
    goal(
        "median driven/planned information",
        new.and_then(|n| n.driven_over_planned_median),
        Target::AtLeast,
        0.95,
        &|| new.map(ratio_shortfall),
    );
    goal(
        "information against the fastest path",
        vs_shortest.and_then(|p| p.median_gain),
        Target::AtLeast,
        0.75,
        &|| {
            Some(information_shortfall(
                new?,
                of(Variant::FastestPath)?,
                vs_shortest?,
            ))
        },
    );
    goal(
        "information against the paper's planner alone (plain)",
        vs_plain.and_then(|p| p.median_gain),
        Target::AtLeast,
        0.30,
        &|| Some(information_shortfall(new?, of(Variant::Plain)?, vs_plain?)),
    );
    goal(
        "no_peb halted steps a day",
        no_peb.and_then(|n| n.halted_steps_per_day_median),
        Target::AtMost,
        HALTED_STEPS_SHARE * HALTED_STEPS_BEFORE_RECOVERY,
        &|| no_peb.map(halted_shortfall),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_follow_the_figures() {
        assert_eq!(judge(Some(0.91), Target::AtLeast, 0.90), Verdict::Holds);
        assert_eq!(
            judge(Some(0.89), Target::AtLeast, 0.90),
            Verdict::DoesNotHold
        );
        assert_eq!(judge(Some(0.0), Target::AtMost, 0.0), Verdict::Holds);
        assert_eq!(judge(Some(1.0), Target::AtMost, 0.0), Verdict::DoesNotHold);
        assert_eq!(judge(None, Target::AtLeast, 0.9), Verdict::NotMeasured);
        let none = goals(&[], None, None);
        assert_eq!(none.len(), 6);
        assert!(none.iter().all(|g| g.verdict == Verdict::NotMeasured));
    }
}
