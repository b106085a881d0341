//! One rule for judging a paper's claim against our figures, shared by every
//! `roam reproduce …` runner: no verdict is written by hand, so a row reads "does not
//! hold" whenever our figures contradict the paper's.
//!
//! The rule, by the kind of figure the paper reports:
//! - a relative change or a quantity with a range (`Range`): **holds** when each of ours
//!   (one per goal, mission, …) lies in the paper's range, **same direction** when each
//!   has the sign of the paper's range but some lie outside it, **does not hold**
//!   otherwise (any of ours with the other sign, or zero where the paper reports a
//!   change). A single published value v is the range v ± |v|/4 ([`PaperFigure::about`]):
//!   a quarter either way, so a figure read off a plot or rounded in the text can hold;
//! - a count (`Count`): **holds** when ours equals the paper's, **same direction** when
//!   both are zero or both are not, **does not hold** otherwise;
//! - a yes/no property (`Yes`: "plain APF fails ES1", "the learner beats recency"): ours
//!   is 1 where the property is true of our figures and 0 where it is false; **holds**
//!   when every one of ours agrees with the paper, **does not hold** otherwise;
//! - **no data** when a figure is missing or not finite (no configuration qualified, no
//!   run succeeded).

use serde::Serialize;

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
    /// A value (often a relative change in percent) in `lo ..= hi`.
    Range { lo: f64, hi: f64 },
    /// A count of `of` things (configurations, runs).
    Count { paper: usize, of: usize },
    /// A property the paper says is true (`true`) or false.
    Yes(bool),
}

impl PaperFigure {
    /// A single published value `v`, judged as the range v ± |v|/4 (module doc).
    pub fn about(v: f64) -> PaperFigure {
        PaperFigure::Range {
            lo: v - v.abs() / 4.0,
            hi: v + v.abs() / 4.0,
        }
    }

    /// The verdict for `ours`, one figure per goal (`expected` of them), by the module
    /// doc's rule.
    pub fn judge(&self, ours: &[f64], expected: usize) -> Verdict {
        if ours.len() < expected || ours.is_empty() || ours.iter().any(|v| !v.is_finite()) {
            return Verdict::NoData;
        }
        match *self {
            PaperFigure::Range { lo, hi } => {
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
            PaperFigure::Count { paper, .. } => {
                let paper = paper as f64;
                if ours.iter().all(|v| *v == paper) {
                    Verdict::Holds
                } else if ours.iter().all(|v| (*v > 0.0) == (paper > 0.0)) {
                    Verdict::SameDirection
                } else {
                    Verdict::DoesNotHold
                }
            }
            PaperFigure::Yes(paper) => {
                if ours.iter().all(|v| (*v > 0.5) == paper) {
                    Verdict::Holds
                } else {
                    Verdict::DoesNotHold
                }
            }
        }
    }

    /// The paper's figure as text.
    pub fn describe(&self) -> String {
        match *self {
            PaperFigure::Range { lo, hi } if lo == hi => format!("{lo:+.2}"),
            PaperFigure::Range { lo, hi } => format!("{lo:+.2} to {hi:+.2}"),
            PaperFigure::Count { paper, of } => format!("{paper} of {of}"),
            PaperFigure::Yes(true) => "yes".into(),
            PaperFigure::Yes(false) => "no".into(),
        }
    }
}

/// Our figure next to the paper's for one claim, with the verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    pub claim: String,
    pub paper: String,
    pub ours: String,
    pub verdict: Verdict,
}

impl Comparison {
    /// Judges `ours` (one figure per goal, `expected` of them) against `paper`;
    /// `paper_note` (may be empty) says where the paper's figure comes from, `ours_text`
    /// how ours reads.
    pub fn judged(
        claim: impl Into<String>,
        paper: PaperFigure,
        paper_note: &str,
        ours: &[f64],
        ours_text: String,
        expected: usize,
    ) -> Comparison {
        let mut paper_text = paper.describe();
        if !paper_note.is_empty() {
            paper_text = format!("{paper_text} ({paper_note})");
        }
        Comparison {
            claim: claim.into(),
            paper: paper_text,
            ours: ours_text,
            verdict: paper.judge(ours, expected),
        }
    }

    /// A yes/no claim: `ours` is whether the property is true of our figures (`None`:
    /// no figure to say).
    pub fn yes_no(
        claim: impl Into<String>,
        paper: bool,
        paper_note: &str,
        ours: Option<bool>,
        ours_text: String,
    ) -> Comparison {
        let ours: Vec<f64> = ours.map(|b| f64::from(u8::from(b))).into_iter().collect();
        Comparison::judged(
            claim,
            PaperFigure::Yes(paper),
            paper_note,
            &ours,
            ours_text,
            1,
        )
    }
}

/// Relative change of `a` over `b`, percent.
pub fn percent_change(a: f64, b: f64) -> f64 {
    (a / b - 1.0) * 100.0
}

/// A plain-text block of comparisons for the terminal, one line each.
pub fn lines(comparisons: &[Comparison]) -> String {
    let mut out = String::new();
    for c in comparisons {
        out.push_str(&format!(
            "  {}: paper {}, ours {}: {}\n",
            c.claim,
            c.paper,
            c.ours,
            c.verdict.as_str()
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const RANGE: PaperFigure = PaperFigure::Range {
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
    fn a_missing_figure_is_no_data_not_a_verdict() {
        assert_eq!(RANGE.judge(&[-20.0], 2), Verdict::NoData);
        assert_eq!(RANGE.judge(&[], 2), Verdict::NoData);
        assert_eq!(RANGE.judge(&[f64::NAN, -20.0], 2), Verdict::NoData);
        assert_eq!(
            Comparison::yes_no("x", true, "", None, "-".into()).verdict,
            Verdict::NoData
        );
    }

    #[test]
    fn counts_must_match_the_paper() {
        let count = |paper| PaperFigure::Count { paper, of: 6 };
        assert_eq!(count(1).judge(&[0.0], 1), Verdict::DoesNotHold);
        assert_eq!(count(3).judge(&[0.0], 1), Verdict::DoesNotHold);
        assert_eq!(count(0).judge(&[0.0], 1), Verdict::Holds);
        assert_eq!(count(0).judge(&[2.0], 1), Verdict::DoesNotHold);
        assert_eq!(count(3).judge(&[5.0], 1), Verdict::SameDirection);
        assert_eq!(count(3).describe(), "3 of 6");
    }

    #[test]
    fn a_single_value_holds_within_a_quarter_of_it() {
        let v = PaperFigure::about(-3.13);
        assert_eq!(v.judge(&[-3.5], 1), Verdict::Holds);
        assert_eq!(v.judge(&[-2.4], 1), Verdict::Holds);
        assert_eq!(v.judge(&[-2.3], 1), Verdict::SameDirection);
        assert_eq!(v.judge(&[-9.0], 1), Verdict::SameDirection);
        assert_eq!(v.judge(&[1.0], 1), Verdict::DoesNotHold);
    }

    #[test]
    fn a_yes_no_claim_holds_only_when_ours_agrees() {
        let c = |paper, ours| Comparison::yes_no("c", paper, "", Some(ours), String::new());
        assert_eq!(c(true, true).verdict, Verdict::Holds);
        assert_eq!(c(false, false).verdict, Verdict::Holds);
        assert_eq!(c(true, false).verdict, Verdict::DoesNotHold);
        assert_eq!(c(false, true).verdict, Verdict::DoesNotHold);
    }
}
