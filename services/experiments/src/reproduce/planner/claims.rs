//! Paper 000's claims (§III.B and the abstract) with ours beside them, and a verdict
//! computed from both figures: no verdict is written by hand, so a row says "does not
//! hold" whenever our figures contradict the paper's.
//!
//! The rule is [`crate::verdict`]'s, one for every reproduction: a relative change holds
//! when each goal's lies in the paper's range, a count of configurations when it equals
//! the paper's; **no data** when a goal has no figure (no configuration qualified, e.g.
//! none of a model's configurations kept every run within budget).

use super::row::Row;
use super::setup::GOALS;
use crate::verdict::{percent_change, Comparison, PaperFigure};

fn find<'a>(rows: &'a [Row], goal: &str, ratio: &str, model: &str) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.goal == goal && r.ratio == ratio && r.model == model)
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
            best_median.push(percent_change(m1.u_ges_median, m0.u_ges_median));
            best_mean.push(percent_change(m1.u_ges_mean, m0.u_ges_mean));
            configs.push(format!("{goal}: I {} vs 0 {}", m1.ratio, m0.ratio));
        }
        if let (Some(m1), Some(m0)) = (
            find(rows, goal, "40/60", "model1"),
            find(rows, goal, "20/80", "model0"),
        ) {
            fixed.push(percent_change(m1.u_ges_median, m0.u_ges_median));
        }
        if let (Some(m2_best), Some(m0)) = (
            best_valid(rows, goal, "model2"),
            best_valid(rows, goal, "model0"),
        ) {
            m2.push(percent_change(m2_best.u_ges_median, m0.u_ges_median));
        }
    }
    // Table II's spreads over the two goals.
    let model1_gain = PaperFigure::Range {
        lo: 10.29,
        hi: 33.61,
    };
    let mut out = vec![
        Comparison::judged(
            format!(
                "best valid Model I vs best valid Model 0, median U_ges % change, goal 1 / goal 2 ({})",
                configs.join("; ")
            ),
            model1_gain,
            "I 40/60 vs 0 20/80",
            &best_median,
            percents(&best_median),
            goals,
        ),
        Comparison::judged(
            "best valid Model I vs best valid Model 0, mean U_ges % change",
            PaperFigure::Range {
                lo: 14.37,
                hi: 29.14,
            },
            "",
            &best_mean,
            percents(&best_mean),
            goals,
        ),
        Comparison::judged(
            "Model I at 40/60 vs Model 0 at 20/80 (the paper's best pair), median U_ges % change",
            model1_gain,
            "",
            &fixed,
            percents(&fixed),
            goals,
        ),
        Comparison::judged(
            "best valid Model II vs best valid Model 0, median U_ges % change",
            PaperFigure::Range {
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
        out.push(Comparison::judged(
            format!("{model} configurations with any run over budget"),
            PaperFigure::Count {
                paper,
                of: cfgs.len(),
            },
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
    use crate::verdict::Verdict;

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
        assert_eq!(
            verdict("median U_ges % change, goal 1"),
            Some(Verdict::Holds)
        );
    }
}
