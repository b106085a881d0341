//! `roam reproduce mission` (without `--days`): the papers joined, with each joining
//! claim judged on the batch's figures by [`crate::verdict`]'s rule.
//!
//! None of the papers runs the three together, so the claims are what each paper
//! promises the joined system, stated so our figures can contradict them:
//! - paper 000 (§III.B, Table II): a curious path gathers more information than the
//!   shortest path, and every plan fits its budget, so the robot driving it arrives in
//!   time on every mission;
//! - paper 002 (§2.2, the PEB as the cost of poor coverage): planning with roam's
//!   localizability cost (W_loc · Σ PEB) lowers the mean PEB along the driven path;
//! - paper 004 (§3, change-based exploration): in a world where nothing changes, the
//!   change probability is no news, so planning on it gathers no more than the shortest
//!   path (within 10 % of it: the planner still turns where the cell path turns);
//! - roam's own (issue 14): the robot drives at least 95 % of the information it planned
//!   (the median of driven / planned over the missions).

use crate::reproduce::mission::missions::{MissionReproduction, VariantResult};
use serde::Serialize;

use crate::verdict::{percent_change, Comparison};

/// The batch's figures and the claims judged on them: what `--json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct MissionReport {
    #[serde(flatten)]
    pub reproduction: MissionReproduction,
    pub claims: Vec<Comparison>,
}

/// The least median driven / planned information that meets roam's goal.
pub const DRIVEN_OVER_PLANNED_GOAL: f64 = 0.95;

/// How far (percent) the change-planned variant may gather more than the shortest path
/// in a world without changes and still count as "no more".
pub const NO_NEWS_TOLERANCE_PCT: f64 = 10.0;

fn variant<'a>(r: &'a MissionReproduction, name: &str) -> Option<&'a VariantResult> {
    r.variants.iter().find(|v| v.variant == name)
}

/// The joining claims, each with its computed verdict.
pub fn claims(r: &MissionReproduction) -> Vec<Comparison> {
    let (curious, peb, change, shortest) = (
        variant(r, "static"),
        variant(r, "peb_cost"),
        variant(r, "change"),
        variant(r, "shortest"),
    );
    let mut out = Vec::new();
    let gain = curious
        .zip(shortest)
        .map(|(c, s)| percent_change(c.information, s.information));
    out.push(Comparison::yes_no(
        "paper 000: the curious path (static map) gathers more information than the shortest",
        true,
        "Table II",
        gain.map(|g| g > 0.0),
        gain.map_or_else(|| "-".into(), |g| format!("{g:+.1}% information driven")),
    ));
    out.push(Comparison::yes_no(
        "paper 000: every curious mission arrives within its budget",
        true,
        "§III.B, every valid plan fits t_exec",
        curious.map(|c| c.on_time_share >= 1.0),
        curious.map_or_else(
            || "-".into(),
            |c| format!("{:.0}% on time", 100.0 * c.on_time_share),
        ),
    ));
    let peb_change = peb
        .zip(curious)
        .map(|(p, c)| percent_change(p.peb_mean_m, c.peb_mean_m));
    out.push(Comparison::yes_no(
        "paper 002: the localizability cost lowers the mean PEB along the driven path",
        true,
        "§2.2",
        peb_change.map(|d| d < 0.0),
        peb_change.map_or_else(|| "-".into(), |d| format!("{d:+.1}% mean PEB vs static")),
    ));
    let no_news = change
        .zip(shortest)
        .map(|(c, s)| percent_change(c.information, s.information));
    out.push(Comparison::yes_no(
        format!(
            "paper 004: with nothing changing, planning on the change probability gathers no \
             more than the shortest path (within {NO_NEWS_TOLERANCE_PCT:.0}%)"
        ),
        true,
        "§3",
        no_news.map(|g| g <= NO_NEWS_TOLERANCE_PCT),
        no_news.map_or_else(|| "-".into(), |g| format!("{g:+.1}% vs shortest")),
    ));
    let driven = curious.and_then(|c| c.driven_over_planned_median);
    out.push(Comparison::yes_no(
        format!(
            "roam: the robot drives at least {:.0}% of the information it planned (median)",
            100.0 * DRIVEN_OVER_PLANNED_GOAL
        ),
        true,
        "issue 14's goal",
        driven.map(|d| d >= DRIVEN_OVER_PLANNED_GOAL),
        driven.map_or_else(|| "-".into(), |d| format!("{d:.3}")),
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verdict::Verdict;

    fn v(variant: &'static str, information: f64, on_time: f64, peb: f64) -> VariantResult {
        VariantResult {
            variant,
            information,
            on_time_share: on_time,
            peb_mean_m: peb,
            planned_information: information,
            per_mission: Vec::new(),
            driven_over_planned_median: Some(1.0),
        }
    }

    fn report(variants: Vec<VariantResult>) -> Vec<Verdict> {
        claims(&MissionReproduction {
            missions: 1,
            seed: 0,
            variants,
        })
        .iter()
        .map(|c| c.verdict)
        .collect()
    }

    #[test]
    fn figures_that_meet_every_claim_hold() {
        let verdicts = report(vec![
            v("static", 200.0, 1.0, 0.12),
            v("peb_cost", 190.0, 1.0, 0.11),
            v("change", 105.0, 1.0, 0.11),
            v("shortest", 100.0, 1.0, 0.11),
        ]);
        assert_eq!(verdicts, [Verdict::Holds; 5]);
    }

    #[test]
    fn figures_that_contradict_each_claim_do_not_hold() {
        let mut worse = v("static", 90.0, 0.95, 0.10);
        worse.driven_over_planned_median = Some(0.8);
        let verdicts = report(vec![
            worse,
            v("peb_cost", 190.0, 1.0, 0.11),
            v("change", 120.0, 1.0, 0.11),
            v("shortest", 100.0, 1.0, 0.11),
        ]);
        assert_eq!(verdicts, [Verdict::DoesNotHold; 5]);
    }

    #[test]
    fn a_missing_variant_is_no_data() {
        let verdicts = report(vec![v("static", 200.0, 1.0, 0.12)]);
        assert_eq!(verdicts[0], Verdict::NoData);
        assert_eq!(verdicts[1], Verdict::Holds);
        assert_eq!(verdicts[2], Verdict::NoData);
    }
}
