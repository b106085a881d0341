//! The stack's report: what `roam stack --once` prints and writes after fetching every
//! layer through Zenoh, as any client would.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use roam_planner::client::PlannerClient;
use roam_proto::cells::Cells;
use roam_proto::keys;
use roam_proto::map::{Layer, LayerList};
use roam_proto::map::{INFORMATION_LAYER as INFORMATION, OCCUPANCY_LAYER as OCCUPANCY};
use roam_proto::planner::{GaOverrides, Plan, PlanRequest, PlannerModel, ShortestPathUse};
use roam_runtime::{ClientError, Requester};
use roam_world::grid::Grid;
use roam_world::legend::{framed, Entry, Frame};
use roam_world::render::{
    draw_marker, draw_path, render_map, BASELINE, INFORMATION as INTEREST, MARKER, OCCUPIED, PATH,
};
use serde::Serialize;

/// One layer as the report shows it.
#[derive(Debug, Clone, Serialize)]
pub struct LayerSummary {
    pub name: String,
    pub version: u64,
    pub width: u32,
    pub height: u32,
    pub resolution: f64,
    pub dtype: &'static str,
    /// Milliseconds for the `get` and the decode of this layer.
    pub get_ms: f64,
}

/// A downtime trip to plan: from `start` to `goal` (world metres).
#[derive(Debug, Clone, Serialize)]
pub struct Mission {
    pub name: String,
    pub start: [f64; 2],
    pub goal: [f64; 2],
}

/// One mission's outcome: the curious plan against the shortest path in the same
/// downtime (twice the shortest path's ETA).
#[derive(Debug, Clone, Serialize)]
pub struct MissionReport {
    pub name: String,
    pub budget_s: f64,
    pub shortest_eta_s: f64,
    pub shortest_information: f64,
    pub curious_eta_s: f64,
    pub curious_information: f64,
    pub curious_reaches_goal: bool,
    pub curious_within_budget: bool,
    pub generations: u32,
    pub planning_ms: f64,
    pub instance: String,
}

/// The report of a stack run.
#[derive(Debug, Clone, Serialize)]
pub struct StackReport {
    pub root: String,
    pub router: String,
    pub layers: Vec<LayerSummary>,
    pub missions: Vec<MissionReport>,
    pub warnings: Vec<String>,
    pub picture: Option<PathBuf>,
}

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error(transparent)]
    Client(#[from] ClientError),
    #[error("cannot write {path}: {reason}")]
    Write { path: PathBuf, reason: String },
}

/// Fetches every layer from the map server through Zenoh, plans each mission with the
/// planner (Model I against the shortest path), and draws the world with the paths to
/// `<out_dir>/world.png`.
pub async fn build(
    requester: &Requester,
    root: &str,
    router: &str,
    missions: &[Mission],
    out_dir: &Path,
) -> Result<StackReport, ReportError> {
    let list: LayerList = requester
        .request::<LayerList, LayerList>(&keys::map_index(root), None)
        .await?;
    let mut layers = Vec::new();
    let mut occupancy = None;
    let mut information = None;
    for info in &list.layers {
        let started = Instant::now();
        let layer: Layer = requester
            .request::<Layer, Layer>(&keys::map_layer(root, &info.name), None)
            .await?;
        let get_ms = ms(started.elapsed());
        layers.push(LayerSummary {
            name: layer.name.clone(),
            version: layer.version,
            width: layer.meta.width,
            height: layer.meta.height,
            resolution: layer.meta.resolution,
            dtype: layer.cells.dtype().as_str(),
            get_ms,
        });
        match (layer.name.as_str(), layer.cells) {
            (OCCUPANCY, Cells::I8(cells)) => {
                occupancy = Some(Grid {
                    meta: layer.meta,
                    cells,
                })
            }
            (INFORMATION, Cells::U8(cells)) => {
                information = Some(Grid {
                    meta: layer.meta,
                    cells,
                })
            }
            _ => {}
        }
    }
    let planner = PlannerClient::new(requester.session().clone(), root);
    let mut mission_reports = Vec::new();
    let mut drawn: Vec<(Plan, Plan)> = Vec::new();
    for mission in missions {
        let (report, shortest, curious) = plan_mission(&planner, mission).await?;
        mission_reports.push(report);
        drawn.push((shortest, curious));
    }
    let picture = match &occupancy {
        Some(occ) => {
            std::fs::create_dir_all(out_dir).map_err(|e| write_error(out_dir, e))?;
            let path = out_dir.join("world.png");
            let scale = (800 / occ.meta.width.max(occ.meta.height)).clamp(1, 8);
            let mut image = render_map(occ, information.as_ref(), scale);
            for (shortest, curious) in &drawn {
                draw_path(
                    &mut image,
                    occ.meta.height,
                    &shortest.cells,
                    scale,
                    BASELINE,
                );
                draw_path(&mut image, occ.meta.height, &curious.cells, scale, PATH);
                for end in [curious.cells.first(), curious.cells.last()]
                    .into_iter()
                    .flatten()
                {
                    draw_marker(&mut image, occ.meta.height, *end, scale, MARKER);
                }
            }
            let frame = picture_frame(root, f64::from(scale) / occ.meta.resolution);
            framed(&image, &frame)
                .save(&path)
                .map_err(|e| ReportError::Write {
                    path: path.clone(),
                    reason: e.to_string(),
                })?;
            Some(path)
        }
        None => None,
    };
    Ok(StackReport {
        root: root.to_owned(),
        router: router.to_owned(),
        layers,
        missions: mission_reports,
        warnings: list.warnings,
        picture,
    })
}

/// The title, legend and scale bar of the stack's `world.png`.
pub fn picture_frame(root: &str, pixels_per_metre: f64) -> Frame {
    Frame {
        title: vec![
            format!("roam stack --once under '{root}': the world and the downtime missions"),
            format!("Model I (1000 generations, seed {REPORT_SEED}) against the shortest path"),
        ],
        legend: vec![
            Entry::fill(INTEREST, "zone of interest (darker: more)"),
            Entry::fill(OCCUPIED, "wall"),
            Entry::line(PATH, "curious plan (Model I)"),
            Entry::line(BASELINE, "shortest path"),
            Entry::fill(MARKER, "start and goal"),
        ],
        text_scale: 2,
        pixels_per_metre: Some(pixels_per_metre),
    }
}

/// The seed every report plan uses, so the report is the same run after run.
pub const REPORT_SEED: u64 = 2024;

async fn plan_mission(
    planner: &PlannerClient,
    mission: &Mission,
) -> Result<(MissionReport, Plan, Plan), ReportError> {
    let mut request = PlanRequest {
        request_id: None,
        cancel_token: None,
        start: mission.start,
        goal: mission.goal,
        t_exec_s: 86_400.0,
        deadline_s: 5.0,
        model: PlannerModel::Shortest,
        params: GaOverrides::default(),
        seed: REPORT_SEED,
        map_version: None,
        shortest: ShortestPathUse::Omit,
        seed_route: Vec::new(),
    };
    let shortest = planner.plan(&request).await?;
    request.t_exec_s = 2.0 * shortest.t_eta_s;
    request.model = PlannerModel::Model1;
    request.params.max_generations = Some(1000);
    request.map_version = Some(shortest.map_version);
    let curious = planner.plan(&request).await?;
    let report = MissionReport {
        name: mission.name.clone(),
        budget_s: request.t_exec_s,
        shortest_eta_s: shortest.t_eta_s,
        shortest_information: shortest.distinct_information,
        curious_eta_s: curious.t_eta_s,
        curious_information: curious.distinct_information,
        curious_reaches_goal: curious.reaches_goal,
        curious_within_budget: curious.within_budget,
        generations: curious.generations,
        planning_ms: curious.planning_ms,
        instance: curious.instance.clone(),
    };
    Ok((report, shortest, curious))
}

fn write_error(path: &Path, e: std::io::Error) -> ReportError {
    ReportError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    }
}

pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1000.0
}

impl std::fmt::Display for StackReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "roam stack under '{}', router {}",
            self.root, self.router
        )?;
        writeln!(
            f,
            "{:<14} {:>7} {:>11} {:>10} {:>5} {:>9}",
            "layer", "version", "cells", "m/cell", "type", "get ms"
        )?;
        for l in &self.layers {
            writeln!(
                f,
                "{:<14} {:>7} {:>11} {:>10.3} {:>5} {:>9.2}",
                l.name,
                l.version,
                format!("{}x{}", l.width, l.height),
                l.resolution,
                l.dtype,
                l.get_ms
            )?;
        }
        if !self.missions.is_empty() {
            writeln!(
                f,
                "\ndowntime missions (Model I vs the shortest path, budget = 2 x shortest ETA):"
            )?;
            writeln!(
                f,
                "{:<16} {:>8} {:>10} {:>10} {:>10} {:>10} {:>6} {:>9}",
                "mission",
                "budget s",
                "short. s",
                "short. I",
                "curious s",
                "curious I",
                "gain",
                "plan ms"
            )?;
            for m in &self.missions {
                let gain = if m.shortest_information > 0.0 {
                    (m.curious_information / m.shortest_information - 1.0) * 100.0
                } else {
                    0.0
                };
                writeln!(
                    f,
                    "{:<16} {:>8.1} {:>10.1} {:>10.0} {:>10.1} {:>10.0} {:>5.0}% {:>9.0}{}",
                    m.name,
                    m.budget_s,
                    m.shortest_eta_s,
                    m.shortest_information,
                    m.curious_eta_s,
                    m.curious_information,
                    gain,
                    m.planning_ms,
                    if m.curious_reaches_goal && m.curious_within_budget {
                        ""
                    } else {
                        "  (misses goal or budget)"
                    }
                )?;
            }
        }
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        if let Some(p) = &self.picture {
            writeln!(f, "picture: {}", p.display())?;
        }
        Ok(())
    }
}
