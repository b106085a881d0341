//! The demo's day driven: the layers fetched, the robot's true path recorded, the
//! executive run, the picture drawn, the one-plan baseline replayed, the report written.

use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use roam_mission::baseline::one_plan_per_window;
use roam_mission::executive::{self, ExecutiveConfig, Progress};
use roam_proto::cells::Cells;
use roam_proto::map::Layer;
use roam_proto::map::{
    INFLATED_LAYER as INFLATED, INFORMATION_LAYER as INFORMATION, OCCUPANCY_LAYER as OCCUPANCY,
};
use roam_proto::mission::WindowReport;
use roam_proto::sim::GroundTruth;
use roam_proto::{decode, keys};
use roam_runtime::Requester;
use roam_stack::stack::Stack;
use roam_world::grid::Grid;
use roam_world::legend::framed;
use tokio_util::sync::CancellationToken;

use crate::demo_picture::{self, Day};

use super::error::{write_error, DemoError};
use super::options::{DemoOptions, DEMO_W_LOC};
use super::report::{markdown, DemoReport};

pub(super) async fn drive(
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
