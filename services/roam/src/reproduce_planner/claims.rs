//! Paper 000's claims (§III.B and the abstract) with ours beside them, and a verdict
//! computed from both figures: no verdict is written by hand, so a row says "does not
//! hold" whenever our figures contradict the paper's.
//!
//! The rule, one for every claim:
//! - a relative change (percent): **holds** when each of ours (one per goal) lies in the
//!   paper's range, **same direction** when each has the sign of the paper's range but
//!   some lie outside it, **does not hold** otherwise (any of ours with the other sign,
//!   or zero where the paper reports a change);
//! - a count of configurations: **holds** when ours equals the paper's, **same
//!   direction** when both are zero or both are not, **does not hold** otherwise;
//! - **no data** when a goal has no figure (no configuration qualified, e.g. none of a
//!   model's configurations kept every run within budget).

use serde::Serialize;

use super::{Row, GOALS};

/// How our figures relate to the paper's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Holds,
    SameDirection,
    DoesNotHold,
    NoData,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Holds => "holds",
            Verdict::SameDirection => "same direction, outside the paper's range",
            Verdict::DoesNotHold => "does not hold",
            Verdict::NoData => "no data",
        }
    }
}

/// What the paper reports for one claim, as a figure ours can be judged against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PaperFigure {
    /// A relative change in percent over the paper's goals, `lo ≤ hi`.
    Percent { lo: f64, hi: f64 },
    /// A number of configurations.
    Count(usize),
}

impl PaperFigure {
    /// The verdict for `ours`, one figure per goal (`expected` of them), by the module
    /// doc's rule.
    pub fn judge(&self, ours: &[f64], expected: usize) -> Verdict {
        if ours.len() < expected || ours.is_empty() || ours.iter().any(|v| !v.is_finite()) {
            return Verdict::NoData;
        }
        match *self {
            PaperFigure::Percent { lo, hi } => {
                if ours.iter().all(|v| (lo..=hi).contains(v)) {
                    Verdict::Holds
                } else if lo.signum() == hi.signum()
                    && lo != 0.0
                    && ours.iter().all(|v| *v != 0.0 && v.signum() == lo.signum())
                {
                    Verdict::SameDirection
                } else {
                    Verdict::DoesNotHold
                }
            }
            PaperFigure::Count(paper) => {
                let paper = paper as f64;
                if ours.iter().all(|v| *v == paper) {
                    Verdict::Holds
                } else if ours.iter().all(|v| (*v > 0.0) == (paper > 0.0)) {
                    Verdict::SameDirection
                } else {
                    Verdict::DoesNotHold
                }
            }
        }
    }

    fn describe(&self) -> String {
        match *self {
            PaperFigure::Percent { lo, hi } => format!("{lo:+.2}% to {hi:+.2}%"),
            PaperFigure::Count(n) => format!("{n} of 6"),
        }
    }
}

/// Our figure next to the paper's for one claim.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    pub claim: String,
    pub paper: String,
    pub ours: String,
    pub verdict: Verdict,
}

fn comparison(
    claim: String,
    paper: PaperFigure,
    note: &str,
    ours: &[f64],
    ours_text: String,
    expected: usize,
) -> Comparison {
    let mut paper_text = paper.describe();
    if !note.is_empty() {
        paper_text = format!("{paper_text} ({note})");
    }
    Comparison {
        claim,
        paper: paper_text,
        ours: ours_text,
        verdict: paper.judge(ours, expected),
    }
}

fn find<'a>(rows: &'a [Row], goal: &str, ratio: &str, model: &str) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.goal == goal && r.ratio == ratio && r.model == model)
}

/// Relative change of `a` over `b`, percent.
fn pct(a: f64, b: f64) -> f64 {
    (a / b - 1.0) * 100.0
}

/// The best configuration of a model for a goal: the highest median U_ges among the
/// configurations whose runs all fit the budget (the paper greys out the others).
fn best_valid<'a>(rows: &'a [Row], goal: &str, model: &str) -> Option<&'a Row> {
    rows.iter()
        .filter(|r| r.goal == goal && r.model == model && r.within_budget >= 1.0)
        .max_by(|a, b| a.u_ges_median.total_cmp(&b.u_ges_median))
}

fn percents(v: &[f64]) -> String {
    if v.is_empty() {
        return "none".into();
    }
    v.iter()
        .map(|g| format!("{g:+.2}%"))
        .collect::<Vec<_>>()
        .join(" / ")
}

/// The paper's claims, ours next to theirs, each with its computed verdict.
pub fn compare(rows: &[Row]) -> Vec<Comparison> {
    let goals = GOALS.len();
    let (mut best_median, mut best_mean, mut fixed, mut m2, mut configs) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (goal, _) in GOALS {
        if let (Some(m1), Some(m0)) = (
            best_valid(rows, goal, "model1"),
            best_valid(rows, goal, "model0"),
        ) {
            best_median.push(pct(m1.u_ges_median, m0.u_ges_median));
            best_mean.push(pct(m1.u_ges_mean, m0.u_ges_mean));
            configs.push(format!("{goal}: I {} vs 0 {}", m1.ratio, m0.ratio));
        }
        if let (Some(m1), Some(m0)) = (
            find(rows, goal, "40/60", "model1"),
            find(rows, goal, "20/80", "model0"),
        ) {
            fixed.push(pct(m1.u_ges_median, m0.u_ges_median));
        }
        if let (Some(m2_best), Some(m0)) = (
            best_valid(rows, goal, "model2"),
            best_valid(rows, goal, "model0"),
        ) {
            m2.push(pct(m2_best.u_ges_median, m0.u_ges_median));
        }
    }
    // Table II's spreads over the two goals.
    let model1_gain = PaperFigure::Percent {
        lo: 10.29,
        hi: 33.61,
    };
    let mut out = vec![
        comparison(
            format!(
                "best valid Model I vs best valid Model 0, median U_ges, goal 1 / goal 2 ({})",
                configs.join("; ")
            ),
            model1_gain,
            "I 40/60 vs 0 20/80",
            &best_median,
            percents(&best_median),
            goals,
        ),
        comparison(
            "best valid Model I vs best valid Model 0, mean U_ges".into(),
            PaperFigure::Percent {
                lo: 14.37,
                hi: 29.14,
            },
            "",
            &best_mean,
            percents(&best_mean),
            goals,
        ),
        comparison(
            "Model I at 40/60 vs Model 0 at 20/80 (the paper's best pair), median U_ges".into(),
            model1_gain,
            "",
            &fixed,
            percents(&fixed),
            goals,
        ),
        comparison(
            "best valid Model II vs best valid Model 0, median U_ges".into(),
            PaperFigure::Percent {
                lo: -26.30,
                hi: -18.96,
            },
            "Model II starved of generations",
            &m2,
            percents(&m2),
            goals,
        ),
    ];
    for (model, paper, note) in [
        ("model0", 1, "60/40, goal 2"),
        ("model1", 0, ""),
        ("model2", 3, ""),
    ] {
        let cfgs: Vec<&Row> = rows.iter().filter(|r| r.model == model).collect();
        let violating = cfgs.iter().filter(|r| r.within_budget < 1.0).count();
        out.push(comparison(
            format!("{model} configurations with any run over budget"),
            PaperFigure::Count(paper),
            note,
            &[violating as f64],
            format!("{violating} of {}", cfgs.len()),
            1,
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const RANGE: PaperFigure = PaperFigure::Percent {
        lo: -26.30,
        hi: -18.96,
    };

    #[test]
    fn a_change_against_the_papers_sign_does_not_hold() {
        assert_eq!(RANGE.judge(&[29.0, 43.0], 2), Verdict::DoesNotHold);
        assert_eq!(RANGE.judge(&[-20.0, 43.0], 2), Verdict::DoesNotHold);
        assert_eq!(RANGE.judge(&[-20.0, 0.0], 2), Verdict::DoesNotHold);
        assert_eq!(RANGE.judge(&[-20.0, -25.0], 2), Verdict::Holds);
        assert_eq!(RANGE.judge(&[-20.0, -40.0], 2), Verdict::SameDirection);
    }

    #[test]
    fn a_missing_goal_is_no_data_not_a_verdict() {
        assert_eq!(RANGE.judge(&[-20.0], 2), Verdict::NoData);
        assert_eq!(RANGE.judge(&[], 2), Verdict::NoData);
        assert_eq!(RANGE.judge(&[f64::NAN, -20.0], 2), Verdict::NoData);
    }

    #[test]
    fn counts_must_match_the_paper() {
        assert_eq!(PaperFigure::Count(1).judge(&[0.0], 1), Verdict::DoesNotHold);
        assert_eq!(PaperFigure::Count(3).judge(&[0.0], 1), Verdict::DoesNotHold);
        assert_eq!(PaperFigure::Count(0).judge(&[0.0], 1), Verdict::Holds);
        assert_eq!(PaperFigure::Count(0).judge(&[2.0], 1), Verdict::DoesNotHold);
        assert_eq!(
            PaperFigure::Count(3).judge(&[5.0], 1),
            Verdict::SameDirection
        );
    }

    fn row(goal: &str, ratio: &str, model: &str, u: f64, within: f64) -> Row {
        Row {
            goal: goal.into(),
            ratio: ratio.into(),
            model: model.into(),
            u_ges_median: u,
            u_ges_mean: u,
            d_median: 0.0,
            distinct_information_median: 0.0,
            within_budget: within,
            reached_goal: 1.0,
            generations: 1,
            t_exec_s: 1.0,
        }
    }

    /// The case: Model II above Model 0 and no budget violation, where the paper
    /// has Model II below and violations, must read "does not hold".
    #[test]
    fn the_table_says_where_ours_contradicts_the_paper() {
        let mut rows = Vec::new();
        for (goal, _) in GOALS {
            for (ratio, _) in super::super::RATIOS {
                rows.push(row(goal, ratio, "model0", 100.0, 1.0));
                rows.push(row(goal, ratio, "model1", 120.0, 1.0));
                rows.push(row(goal, ratio, "model2", 130.0, 1.0));
            }
        }
        let claims = compare(&rows);
        let verdict = |needle: &str| {
            claims
                .iter()
                .find(|c| c.claim.contains(needle))
                .map(|c| c.verdict)
        };
        assert_eq!(
            verdict("best valid Model II"),
            Some(Verdict::DoesNotHold),
            "{claims:?}"
        );
        assert_eq!(verdict("model0 configurations"), Some(Verdict::DoesNotHold));
        assert_eq!(verdict("model2 configurations"), Some(Verdict::DoesNotHold));
        assert_eq!(verdict("model1 configurations"), Some(Verdict::Holds));
        assert_eq!(verdict("median U_ges, goal 1"), Some(Verdict::Holds));
    }
}
