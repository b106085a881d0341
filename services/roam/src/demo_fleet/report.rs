//! What `roam demo --fleet` writes: `report.json` (the run in the batch's figures, its
//! goals and every window) and `report.md`.

use std::path::{Path, PathBuf};

use roam_experiments::reproduce::fleet::FleetSummary;
use roam_proto::mission::WindowReport;
use serde::Serialize;

use crate::demo::{write_error, DemoError};

/// A goal of the live fleet, judged from its figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveGoal {
    pub goal: &'static str,
    pub figure: Option<f64>,
    pub at_most: f64,
    pub met: Option<bool>,
}

impl LiveGoal {
    /// `met`, `missed`, or `no figure`.
    pub fn verdict(&self) -> &'static str {
        match self.met {
            Some(true) => "met",
            Some(false) => "missed",
            None => "no figure",
        }
    }

    pub(super) fn at_most(goal: &'static str, figure: Option<f64>, at_most: f64) -> LiveGoal {
        LiveGoal {
            goal,
            figure,
            at_most,
            met: figure.map(|f| f <= at_most),
        }
    }
}

/// `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FleetDemoReport {
    pub robots: usize,
    pub shift_s: f64,
    pub sim_rate: f64,
    pub planners: usize,
    pub seed: u64,
    /// Every task of every robot reached no later than its start.
    pub on_time: bool,
    /// The run in the batch's figures (variant `news`).
    pub summary: FleetSummary,
    pub goals: Vec<LiveGoal>,
    /// Every window, as each robot's executive reported it.
    pub windows: Vec<WindowReport>,
    pub wall_s: f64,
    pub pictures: Vec<PathBuf>,
}

pub(super) fn write_reports(
    dir: &Path,
    report: &FleetDemoReport,
    table: &str,
) -> Result<(), DemoError> {
    let json_path = dir.join("report.json");
    let json = serde_json::to_string_pretty(report).map_err(|e| write_error(&json_path, e))?;
    std::fs::write(&json_path, json).map_err(|e| write_error(&json_path, e))?;
    let md_path = dir.join("report.md");
    std::fs::write(&md_path, markdown(report, table)).map_err(|e| write_error(&md_path, e))?;
    Ok(())
}

fn markdown(r: &FleetDemoReport, table: &str) -> String {
    let mut out = format!(
        "# roam demo --fleet\n\n{} robots in the warehouse (`world.yaml`), each with its own mission executive, the first {:.0} s of their shift, the sim at {}x, {} planners on the fleet's news (seed {}), {:.1} s of wall time.\n\n",
        r.robots, r.shift_s, r.sim_rate, r.planners, r.seed, r.wall_s
    );
    out.push_str("Measured as `roam reproduce fleet` measures a week (its `news` variant):\n\n");
    out.push_str(table);
    out.push_str("\n| goal | figure | at most | verdict |\n|---|---|---|---|\n");
    for g in &r.goals {
        out.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            g.goal,
            g.figure.map_or("-".to_owned(), |f| format!("{f:.1}")),
            g.at_most,
            g.verdict()
        ));
    }
    out.push_str("\n| robot | window | task | task starts s | arrived s | on time | replans | holds |\n|---|---|---|---|---|---|---|---|\n");
    for w in &r.windows {
        out.push_str(&format!(
            "| {} | {} | {} | {:.1} | {} | {} | {} | {} |\n",
            w.robot,
            w.window + 1,
            w.task,
            w.task_start_s,
            w.arrival_s.map_or("-".to_owned(), |a| format!("{a:.1}")),
            if w.on_time { "yes" } else { "no" },
            w.replans,
            w.holds,
        ));
    }
    out.push_str("\n![the warehouse with each robot's driven path](warehouse-news.svg)\n\n![detection latency over the run](detection.svg)\n");
    out
}
