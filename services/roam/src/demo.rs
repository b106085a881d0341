//! `roam demo`: roam's main job on its embedded default. The whole stack boots in one
//! process on the demo's day world (`config/scenarios/day.yaml`, embedded: a moving
//! cart, 3 m observations, a poorly covered north-east room), the sim runs faster than
//! real time, and one robot spends the downtime before each of its four tasks (one a
//! round trip) on a curious path: the mission executive plans it (paper 000) with the
//! robot's own time model and the PEB cost, the controller drives it on the
//! localization's estimates (paper 002), and the run ends with a report directory.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_controller::params::ApfParams;
use roam_mission::executive::{self, ExecutiveConfig, Progress};
use roam_mission::site::Site;
use roam_proto::cells::Cells;
use roam_proto::map::Layer;
use roam_proto::map::{
    INFLATED_LAYER as INFLATED, INFORMATION_LAYER as INFORMATION, OCCUPANCY_LAYER as OCCUPANCY,
};
use roam_proto::mission::WindowReport;
use roam_proto::sim::GroundTruth;
use roam_proto::{decode, keys};
use roam_runtime::Requester;
use roam_world::grid::Grid;
use roam_world::legend::framed;
use serde::Serialize;
use tokio_util::sync::CancellationToken;

use roam_mission::baseline::{one_plan_per_window, BaselinePlan};
use roam_stack::stack::{Stack, StackOptions};

use crate::demo_picture::{self, Day};

/// How the demo runs.
#[derive(Debug, Clone)]
pub struct DemoOptions {
    pub out_dir: PathBuf,
    /// The sim's real-time factor.
    pub rate: f64,
    pub seed: u64,
    /// The key root (a unique one lets several demos share a machine).
    pub root: Option<String>,
    /// The live view and the recording.
    pub view: LiveView,
    /// Offer the demo to ROS 2 (`roam ros2` in the stack).
    pub ros2: Option<roam_ros2::node::Ros2Config>,
    /// The stack router's endpoint, where other processes connect (a ROS 2 system
    /// over rmw_zenoh, `roam plan`, a Zenoh client); a free loopback port when `None`.
    pub listen: Option<String>,
    /// The world and the robot's day: the built-in day, or a user's Nav2 map and day
    /// file ([`roam_mission::site`]).
    pub site: Site,
}

impl Default for DemoOptions {
    fn default() -> Self {
        DemoOptions {
            out_dir: PathBuf::from("roam-demo"),
            rate: 20.0,
            seed: 0,
            root: None,
            view: LiveView::default(),
            ros2: None,
            listen: None,
            site: Site::builtin_day(),
        }
    }
}

/// The live view of a demo, and its recording.
#[derive(Debug, Clone, Default)]
pub struct LiveView {
    /// Serve the live view (a Foxglove WebSocket server) here while the demo runs.
    pub listen: Option<std::net::SocketAddr>,
    /// Record the run to this MCAP file.
    pub record: Option<PathBuf>,
    /// Who may connect to the live view.
    pub access: roam_view::Access,
}

/// The PEB cost the demo's executive plans with (the planner's W_loc, as in `roam
/// reproduce mission`): paths through the poorly covered room cost information.
pub const DEMO_W_LOC: f64 = 2000.0;

/// The controller's parameters for the built-in world: [`ApfParams::indoor`].
pub fn indoor_apf() -> ApfParams {
    ApfParams::indoor()
}

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

#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    #[error(transparent)]
    Stack(#[from] roam_stack::stack::StackError),
    #[error(transparent)]
    Executive(#[from] roam_mission::error::ExecutiveError),
    #[error(transparent)]
    Client(#[from] roam_runtime::ClientError),
    #[error("zenoh: {0}")]
    Zenoh(String),
    #[error(transparent)]
    View(#[from] roam_view::ViewError),
    #[error("cannot write {path}: {reason}")]
    Write { path: PathBuf, reason: String },
    #[error("{field} is {value}; give {limit}")]
    Invalid {
        field: &'static str,
        value: String,
        limit: String,
    },
    #[error("the fleet: {0}")]
    Fleet(String),
}

pub(crate) fn write_error(path: &Path, e: impl std::fmt::Display) -> DemoError {
    DemoError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    }
}

/// Runs the demo and writes `world.png`, `report.json` and `report.md` to the out dir.
pub async fn run(
    options: &DemoOptions,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<DemoReport, DemoError> {
    let started = Instant::now();
    std::fs::create_dir_all(&options.out_dir).map_err(|e| write_error(&options.out_dir, e))?;
    // The day's world goes to every service as a file in the report directory, so the
    // report holds the world it was made on.
    let world = options.out_dir.join("world.yaml");
    std::fs::write(&world, &options.site.scenario_yaml).map_err(|e| write_error(&world, e))?;
    for warning in &options.site.warnings {
        progress(&format!("warning: {warning}"));
    }
    progress("booting the stack (map server, planner, sim, localization, controller, mapper)");
    let stack = Stack::start(
        StackOptions {
            root: options.root.clone(),
            map: Some(world.clone()),
            planners: 1,
            sim_rate: Some(options.rate),
            apf: Some(indoor_apf()),
            ros2: options.ros2.clone(),
            listen: options.listen.clone(),
            ..StackOptions::default()
        },
        Duration::from_secs(30),
    )
    .await?;
    if options.listen.is_some() || options.ros2.is_some() {
        progress(&format!(
            "router {} (root '{}'); connect with --connect {}",
            stack.router.endpoint, stack.root, stack.router.endpoint
        ));
    }
    with_live_view(stack, &options.view, progress, async |stack| {
        drive(stack, options, &world, progress, started).await
    })
    .await
}

/// Serves the live view (when asked for) while `drive` runs on `stack`, then stops the
/// view and the stack whatever `drive` returned.
pub(crate) async fn with_live_view<T>(
    stack: Stack,
    view: &LiveView,
    progress: &(dyn Fn(&str) + Sync),
    drive: impl AsyncFnOnce(&Stack) -> Result<T, DemoError>,
) -> Result<T, DemoError> {
    let view_cancel = CancellationToken::new();
    let view = match start_view(&stack, view, &view_cancel, progress).await {
        Ok(view) => view,
        Err(e) => {
            let _ = stack.shutdown().await;
            return Err(e);
        }
    };
    let result = drive(&stack).await;
    view_cancel.cancel();
    let viewed = match view {
        Some(view) => view.join().await.map(|_| ()),
        None => Ok(()),
    };
    let _ = stack.shutdown().await;
    let report = result?;
    viewed?;
    Ok(report)
}

/// Starts the live view on the stack's router session when `--view` or `--record` asks
/// for it (`roam_view`: maps, robots, anchors, planned and driven paths).
async fn start_view(
    stack: &Stack,
    view: &LiveView,
    cancel: &CancellationToken,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Option<roam_view::ViewHandle>, DemoError> {
    if view.listen.is_none() && view.record.is_none() {
        return Ok(None);
    }
    let config = roam_view::ViewConfig {
        root: stack.root.clone(),
        listen: view.listen,
        mcap: view.record.clone(),
        access: view.access.clone(),
    };
    let view = roam_view::run(stack.router.session.clone(), config, cancel.clone()).await?;
    if let Some(url) = view.websocket_url() {
        progress(&format!(
            "live view: in the Foxglove app, Open connection -> Foxglove WebSocket -> {url}"
        ));
    }
    if let Some(path) = view.mcap_path() {
        progress(&format!("recording to {}", path.display()));
    }
    Ok(Some(view))
}

async fn drive(
    stack: &Stack,
    options: &DemoOptions,
    world: &Path,
    progress: &(dyn Fn(&str) + Sync),
    started: Instant,
) -> Result<DemoReport, DemoError> {
    let session = stack.router.session.clone();
    let root = stack.root.clone();
    let requester = Requester::new(session.clone(), Duration::from_secs(10));
    let occupancy = grid_i8(
        requester
            .request::<Layer, Layer>(&keys::map_layer(&root, OCCUPANCY), None)
            .await?,
    );
    let information = grid_u8(
        requester
            .request::<Layer, Layer>(&keys::map_layer(&root, INFORMATION), None)
            .await?,
    );
    let inflated = grid_i8(
        requester
            .request::<Layer, Layer>(&keys::map_layer(&root, INFLATED), None)
            .await?,
    );
    let truth: Arc<Mutex<Vec<[f64; 2]>>> = Arc::default();
    let recorded = truth.clone();
    let _truth = session
        .declare_subscriber(keys::robot_truth(&root, &options.site.robot))
        .callback(move |sample| {
            if let Ok(t) = decode::<GroundTruth>(&sample.payload().to_bytes()) {
                let mut path = roam_runtime::lock(&recorded);
                // About 25 minutes of sim time at the sim's 0.4 s step: far beyond the demo.
                if path.len() < 4096 {
                    path.push(t.at);
                }
            }
        })
        .await
        .map_err(|e| DemoError::Zenoh(e.to_string()))?;
    let config = ExecutiveConfig {
        seed: options.seed,
        robot: options.site.robot.clone(),
        tasks: options.site.tasks.clone(),
        w_loc: Some(DEMO_W_LOC),
        ..ExecutiveConfig::default()
    };
    let say = |p: Progress| {
        match p {
        Progress::Planned {
            window,
            task,
            budget_s,
            eta_s,
            curious,
            late_probability,
        } => progress(&format!(
            "window {} -> {task}: {} path, downtime budget {budget_s:.1} s, ETA {eta_s:.1} s, P(late) {late_probability:.0e}",
            window + 1,
            if curious { "curious" } else { "fastest" },
        )),
        Progress::Replanned { window, reason } => {
            progress(&format!("window {}: replanned ({reason})", window + 1))
        }
        Progress::Recovering { window, held_s } => progress(&format!(
            "window {}: held {held_s:.1} s for its PEB, driving back to its last fix",
            window + 1
        )),
        Progress::Arrived {
            window,
            task,
            at_s,
            start_s,
        } => progress(&format!(
            "window {}: at {task} at {at_s:.1} s, task starts at {start_s:.1} s",
            window + 1
        )),
        Progress::GaveUp { window, task } => progress(&format!(
            "window {}: gave up on reaching {task}",
            window + 1
        )),
        Progress::Skipped { window, task } => progress(&format!(
            "window {}: {task} was over before the window began",
            window + 1
        )),
        Progress::Answered { .. } => {}
    }
    };
    let cancel = CancellationToken::new();
    let outcomes = executive::run(&session, &root, &config, &cancel, &say, &|_| {}).await?;
    let driven = roam_runtime::lock(&truth).clone();

    let picture = options.out_dir.join("world.png");
    let anchors: Vec<[f64; 2]> = roam_world::scenario::load_or_builtin(Some(world))
        .map(|(_, s)| s.file.anchors.iter().map(|a| a.at).collect())
        .unwrap_or_default();
    let tasks: Vec<[f64; 2]> = config.tasks.iter().map(|t| t.at).collect();
    let map = demo_picture::draw_day(&Day {
        occupancy: &occupancy,
        information: &information,
        outcomes: &outcomes,
        driven: &driven,
        tasks: &tasks,
        anchors: &anchors,
    });
    let frame = demo_picture::frame(
        &options.site.name,
        options.seed,
        options.rate,
        outcomes.len(),
        &occupancy.meta,
    );
    framed(&map, &frame)
        .save(&picture)
        .map_err(|e| write_error(&picture, e))?;

    progress("replaying the one-plan-per-window baseline for comparison");
    let baseline = {
        let (outcomes, generations) = (outcomes.clone(), config.max_generations.unwrap_or(1000));
        let seed = config.seed;
        let information = information.clone();
        tokio::task::spawn_blocking(move || {
            one_plan_per_window(&inflated, &information, &outcomes, generations, seed)
        })
        .await
        .map_err(|e| DemoError::Zenoh(format!("the one-plan baseline: {e}")))?
    };
    let windows: Vec<WindowReport> = outcomes.iter().map(|o| o.report.clone()).collect();
    let pebs: Vec<f64> = windows.iter().filter_map(|w| w.peb_mean_m).collect();
    let report = DemoReport {
        on_time: windows.iter().all(|w| w.on_time),
        information: windows.iter().map(|w| w.driven_information).sum(),
        information_shortest_path: windows.iter().map(|w| w.shortest_information).sum(),
        information_planned: windows.iter().map(|w| w.planned_information).sum(),
        information_baseline_plans: baseline
            .iter()
            .flatten()
            .map(|t| t.planned_information)
            .sum(),
        baseline_plans: baseline,
        peb_mean_m: (!pebs.is_empty()).then(|| pebs.iter().sum::<f64>() / pebs.len() as f64),
        windows,
        site: options.site.name.clone(),
        sim_rate: options.rate,
        seed: options.seed,
        wall_s: started.elapsed().as_secs_f64(),
        picture: picture.clone(),
        driven_path: driven,
    };
    let json_path = options.out_dir.join("report.json");
    let json = serde_json::to_string_pretty(&report).map_err(|e| write_error(&json_path, e))?;
    std::fs::write(&json_path, json).map_err(|e| write_error(&json_path, e))?;
    let md_path = options.out_dir.join("report.md");
    std::fs::write(&md_path, markdown(&report)).map_err(|e| write_error(&md_path, e))?;
    Ok(report)
}

fn grid_i8(layer: Layer) -> Grid<i8> {
    let cells = match layer.cells {
        Cells::I8(c) => c,
        _ => vec![0; layer.meta.cell_count() as usize],
    };
    Grid {
        meta: layer.meta,
        cells,
    }
}

fn grid_u8(layer: Layer) -> Grid<u8> {
    let cells = match layer.cells {
        Cells::U8(c) => c,
        _ => vec![0; layer.meta.cell_count() as usize],
    };
    Grid {
        meta: layer.meta,
        cells,
    }
}

fn markdown(r: &DemoReport) -> String {
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
