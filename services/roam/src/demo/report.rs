//! The demo's report: `report.json` and its `report.md`.

use std::path::PathBuf;

use roam_mission::baseline::BaselinePlan;
use roam_proto::mission::WindowReport;
use serde::Serialize;

/// `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct DemoReport {
    /// Every task reached no later than its start.
    pub on_time: bool,
    /// Information of the distinct cells seen along the driven paths (paper 000's
    /// information map and perception window), summed over the windows.
    pub information: f64,
    /// The same along the shortest paths of the same windows.
    pub information_shortest_path: f64,
    /// The same along the planned curious paths.
    pub information_planned: f64,
    /// What the one-plan baseline (static map, Table I, one plan per window, paper 000's
    /// initialization) would have planned per window ([`roam_mission::baseline`]), and the
    /// information those plans promised, summed.
    pub baseline_plans: Vec<Option<BaselinePlan>>,
    pub information_baseline_plans: f64,
    /// The mean PEB of the estimates along the way, metres.
    pub peb_mean_m: Option<f64>,
    pub windows: Vec<WindowReport>,
    /// The site the day ran on (the built-in day, or the day file's name).
    pub site: String,
    pub sim_rate: f64,
    pub seed: u64,
    pub wall_s: f64,
    pub picture: PathBuf,
    /// The robot's true path (every step), world metres: what `world.png` draws in red.
    pub driven_path: Vec<[f64; 2]>,
}

pub(super) fn markdown(r: &DemoReport) -> String {
    let mut out = String::from("# roam demo\n\n");
    out.push_str(&format!(
        "One robot, a day of {} tasks in {} (`world.yaml`), the sim at {}x (seed {}), {:.1} s of wall time.\n\n",
        r.windows.len(),
        if r.site == roam_mission::site::BUILTIN_DAY {
            "the demo's day world".to_owned()
        } else {
            format!("the site `{}`", r.site)
        },
        r.sim_rate,
        r.seed,
        r.wall_s
    ));
    out.push_str("| window | task | task starts s | arrived s | on time | budget s | share driven | information driven | planned | driven / planned | shortest path | one-plan baseline | v_lin s/m | v_ang s/rad | mean PEB m | replans |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for w in &r.windows {
        let baseline = r
            .baseline_plans
            .iter()
            .flatten()
            .find(|t| t.window == w.window)
            .map_or("-".to_owned(), |t| match t.refused {
                Some(_) => "refused".to_owned(),
                None => format!("{:.0}", t.planned_information),
            });
        let ratio = if w.planned_information > 0.0 {
            format!("{:.2}", w.driven_information / w.planned_information)
        } else {
            "-".to_owned()
        };
        let model = w.time_model;
        out.push_str(&format!(
            "| {} | {} | {:.1} | {} | {} | {:.1} | {} | {:.0} | {:.0} | {ratio} | {:.0} | {baseline} | {} | {} | {} | {} |\n",
            w.window + 1,
            w.task,
            w.task_start_s,
            w.arrival_s.map_or("-".to_owned(), |a| format!("{a:.1}")),
            if w.on_time { "yes" } else { "no" },
            w.budget_s,
            model.map_or("-".to_owned(), |m| format!("{:.0}%", m.driven_share * 100.0)),
            w.driven_information,
            w.planned_information,
            w.shortest_information,
            model.map_or("-".to_owned(), |m| format!("{:.2}", m.v_lin)),
            model.map_or("-".to_owned(), |m| format!("{:.2}", m.v_ang)),
            w.peb_mean_m.map_or("-".to_owned(), |p| format!("{p:.3}")),
            w.replans,
        ));
    }
    let gain = if r.information_shortest_path > 0.0 {
        format!(
            "{:+.0}%",
            (r.information / r.information_shortest_path - 1.0) * 100.0
        )
    } else {
        "-".to_owned()
    };
    let against_baseline = if r.information_baseline_plans > 0.0 {
        format!(
            "{:+.0}%",
            (r.information / r.information_baseline_plans - 1.0) * 100.0
        )
    } else {
        "-".to_owned()
    };
    out.push_str(&format!(
        "\nOn time at every task: **{}**. Information gathered: **{:.0}** against {:.0} on the shortest paths ({gain}) and {:.0} that one plan per window would have planned ({against_baseline}; the baseline: static map, Table I's time model, no replans; what it planned, of which a robot drove 84-89%). Mean PEB {}.\n\n",
        if r.on_time { "yes" } else { "no" },
        r.information,
        r.information_shortest_path,
        r.information_baseline_plans,
        r.peb_mean_m.map_or("-".to_owned(), |p| format!("{p:.3} m")),
    ));
    out.push_str("![the day world with its zones of interest (orange), the curious plans (blue), shortest (magenta) and driven (red) paths, anchors (purple), start and task places (green), each window's number where it began, a legend and a scale bar](world.png)\n");
    out
}
