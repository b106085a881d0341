//! The batch's report as terminal text: the variants, the goals with their verdicts and
//! shortfalls, each coupling's effect, and the executive and the plain planner window by
//! window.

use std::fmt::Write;

use super::goals::Target;
use super::summary::VariantSummary;
use super::variant::Variant;
use super::DaysReport;

fn num(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".to_owned(), |v| format!("{v:.digits$}"))
}

fn pct(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_owned(), |v| format!("{:+.0}%", v * 100.0))
}

fn variants(out: &mut String, r: &DaysReport) {
    let _ = writeln!(
        out,
        "{:<14} {:>6} {:>9} {:>8} {:>9} {:>9} {:>8} {:>7} {:>7} {:>8} {:>8} {:>9} {:>9}",
        "variant",
        "share",
        "late",
        "drv/pln",
        "info/day",
        "plan/day",
        "chg/day",
        "PEB m",
        "halt/d",
        "repl/day",
        "GA/day",
        "model err",
        "refused"
    );
    for v in &r.variants {
        let _ = writeln!(
            out,
            "{:<14} {:>6} {:>9} {:>8} {:>9} {:>9} {:>8} {:>7} {:>7} {:>8} {:>8} {:>9} {:>9}",
            v.variant.name(),
            num(v.share_median, 2),
            format!("{}/{}", v.late, v.windows),
            num(v.driven_over_planned_median, 3),
            num(v.information_per_day_median, 0),
            num(v.planned_information_per_day_median, 0),
            num(v.changing_cells_per_day_median, 0),
            num(v.peb_mean_m, 3),
            num(v.halted_steps_per_day_median, 0),
            num(v.replans_per_day, 1),
            num(v.ga_plans_per_day, 1),
            pct(v.model_error_median),
            // Plans the planner refused / scans localization refused: 0 / 0 when healthy.
            format!("{}/{}", v.refused_plans, v.localization_errors),
        );
    }
}

fn by_window(out: &mut String, v: &VariantSummary) {
    let _ = writeln!(
        out,
        "{} by window of the day (medians over days):",
        v.variant.name()
    );
    let _ = writeln!(
        out,
        "  {:<16} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>5} {:>8} {:>7} {:>7} {:>7} {:>6} {:>5} {:>6} {:>6} {:>6}",
        "window",
        "len s",
        "share",
        "drive s",
        "wait s",
        "held s",
        "early",
        "late",
        "drv/pln",
        "driven",
        "planned",
        "short.",
        "curious",
        "cells",
        "v_lin",
        "v_ang",
        "err"
    );
    for w in &v.by_window {
        let _ = writeln!(
            out,
            "  {:<16} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>5} {:>8} {:>7} {:>7} {:>7} {:>6} {:>5} {:>6} {:>6} {:>6}",
            format!("w{} {}", w.window, w.task),
            num(w.window_s_median, 0),
            num(w.share_median, 2),
            num(w.driving_s_median, 1),
            num(w.waited_for_plan_s_median, 1),
            num(w.held_s_median, 1),
            num(w.early_s_median, 1),
            w.late,
            num(w.driven_over_planned_median, 3),
            num(w.driven_information_median, 0),
            num(w.planned_information_median, 0),
            num(w.shortest_information_median, 0),
            format!("{}/{}", w.curious, w.days),
            num(w.first_plan_cells_median, 0),
            num(w.v_lin_median, 2),
            num(w.v_ang_median, 2),
            pct(w.model_error_median),
        );
    }
}

/// The report as text.
pub fn table(r: &DaysReport) -> String {
    let mut out = format!(
        "the executive's day in batch (its own window machine): {} days of tasks::day() on the day world (config/scenarios/day.yaml; {} cells the cart covers), seed {}, Model I with {} generations, a curious plan costs {:.2} s of wall time and a seeded replan {:.2} s (cut to their deadlines) at {}x, W_loc {}\n",
        r.days, r.changing_cells, r.seed, r.generations, r.plan_wall_s, r.replan_wall_s, r.rate, r.w_loc
    );
    variants(&mut out, r);
    out.push_str(
        "(share, drv/pln: medians over windows; info, plan, chg (changing cells seen), halt: per day, medians over days; model err: (predicted - took) / took)\n\n",
    );
    let _ = writeln!(out, "goals (the shipped executive):");
    for g in &r.goals {
        let target = match g.target {
            Target::AtLeast => ">=",
            Target::AtMost => "<=",
        };
        let percent = g.goal.starts_with("information");
        let (figure, threshold) = if percent {
            (pct(g.figure), format!("{:+.0}%", g.threshold * 100.0))
        } else {
            (num(g.figure, 2), format!("{:.2}", g.threshold))
        };
        let _ = writeln!(
            out,
            "  {:<42} {:>8}  {target} {:<6} {}",
            g.goal,
            figure,
            threshold,
            g.verdict.as_str()
        );
    }
    let shortfalls: Vec<&super::Goal> = r.goals.iter().filter(|g| g.shortfall.is_some()).collect();
    if !shortfalls.is_empty() {
        out.push_str("\nshortfalls, measured:\n");
        for g in shortfalls {
            let _ = writeln!(
                out,
                "  - {}: {}",
                g.goal,
                g.shortfall.as_deref().unwrap_or_default()
            );
        }
    }
    if !r.effects.is_empty() {
        out.push_str("\neach coupling alone on the changing world (the executive against itself without it, the same days):\n");
        for e in &r.effects {
            let _ = writeln!(
                out,
                "  {} ({} vs {}):",
                e.coupling,
                e.with.name(),
                e.without.name()
            );
            for f in &e.figures {
                let _ = writeln!(
                    out,
                    "    {:<32} {:>9} vs {:>9}   paired median difference {:>9}",
                    f.figure,
                    num(f.with, 3),
                    num(f.without, 3),
                    num(f.paired_median_difference, 3)
                );
            }
        }
    }
    for variant in [Variant::Executive, Variant::Plain] {
        if let Some(v) = r.variants.iter().find(|s| s.variant == variant) {
            out.push('\n');
            by_window(&mut out, v);
        }
    }
    out
}
