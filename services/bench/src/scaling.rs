//! `roam bench planner --scaling`: what a plan costs as the map gets finer (issue 16).
//!
//! The paper's workload (Model I, population 200, 2000 generations, seeds 0..runs, from
//! the start to Goal 2) on the same world at 0.2, 0.1, 0.05 and 0.03 m (the built-in
//! 20 × 20 m world, its 0.2 m cells split into finer ones, inflated at each resolution by
//! the robot's radius), with one budget: twice the fastest path's ETA on the 0.2 m world.
//! Each resolution is planned twice: at the planner's default planning resolution (0.2
//! m, or 0.21 m on a 3 cm map: whole map cells) and at the map's own resolution (what the
//! planner did before issue 16). Then a generated 30 × 51 m warehouse at 3 cm (1.7
//! million cells, shelf rows, zones of interest) the same two ways, and the memory of a
//! planner instance holding it.
//!
//! `distinct_information_ref` is the information of the distinct cells seen along the
//! driven path, counted on the 0.2 m world's cells with its perception window (d = 3):
//! the same yardstick at every resolution. Times are medians of wall seconds in process,
//! ratios within one run.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use roam_planner::maps::MapCache;
use roam_planner::metrics::path_metrics;
use roam_planner::params::GaParams;
use roam_planner::plan::{plan, PlanOutcome, PlanSpec};
use roam_planner::world::{Cell, World};
use roam_proto::cells::Cells;
use roam_proto::map::{GridMeta, Layer, Origin};
use roam_proto::planner::PlannerModel;
use roam_world::grid::{cell_center, world_to_cell, Grid};
use roam_world::layers::inflate;
use serde::Serialize;

use crate::{setup, BenchError};

use crate::planner::{builtin_world, GOAL, START};
use crate::process::{peak_rss_mib, process_cpu_seconds, rss_mib};
use roam_experiments::progress::{Done, Progress};

/// The map resolutions of the built-in world the bench plans on.
pub const RESOLUTIONS: [f64; 4] = [0.2, 0.1, 0.05, 0.03];
/// The planner's default planning resolution (paper 000's).
pub const PLANNING_M: f64 = 0.2;

#[derive(Debug, Clone, Serialize)]
pub struct ScalingRow {
    pub world: String,
    /// Ratios are to the row of the same family on its 0.2 m map planned at 0.2 m.
    pub family: String,
    pub map_resolution_m: f64,
    pub map_cells: usize,
    /// The resolution planned at: the planning grid's.
    pub planning_resolution_m: f64,
    pub planning_cells: usize,
    /// Seconds to build the planning grid from the layers (once per map version).
    pub build_s: f64,
    pub plan_s_median: f64,
    /// `plan_s_median` over the 0.2 m world's planned at 0.2 m, in this run.
    pub ratio_to_paper_scale: f64,
    /// CPU seconds of the process per plan (all its evaluation threads; the machine is
    /// shared, so wall time carries other work's load, CPU time does not).
    pub plan_cpu_s_median: f64,
    /// `plan_cpu_s_median` over the 0.2 m world's planned at 0.2 m.
    pub cpu_ratio_to_paper_scale: f64,
    pub distinct_information_ref_median: f64,
    pub t_eta_s_median: f64,
    pub budget_s: f64,
    pub path_cells_median: f64,
    pub within_budget: usize,
    pub runs: usize,
}

#[derive(Debug, Clone, Serialize)]
pub struct MemoryBench {
    pub map_cells: usize,
    /// Resident memory one planner's map cache adds holding the layers and the
    /// planning world built from them, MiB (VmRSS after minus before).
    pub cache_rss_mib: f64,
    /// The same after one plan of the paper's workload on it.
    pub after_plan_rss_mib: f64,
    /// The process's peak so far (VmHWM), MiB.
    pub peak_rss_mib: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ScalingBench {
    /// Planned at the default planning resolution.
    pub planned_coarse: Vec<ScalingRow>,
    /// Planned at the map's own resolution (the planner before issue 16).
    pub planned_at_map_resolution: Vec<ScalingRow>,
    /// Warehouse memory, measured first in a fresh process.
    pub memory: MemoryBench,
    /// The goal: at most this × the 0.2 m time at every resolution.
    pub goal_ratio: f64,
    pub runs: usize,
}

/// The built-in world's layers at `resolution`: each 0.2 m cell split into the finer
/// cells whose centres lie in it, then inflated by the robot's radius at `resolution`.
pub fn builtin_at(resolution: f64) -> Result<(Grid<i8>, Grid<u8>), BenchError> {
    let content =
        roam_map_server::map_file::builtin(roam_map_server::store::DEFAULT_LIMITS.max_layer_cells)
            .map_err(setup)?;
    let information = content
        .information
        .ok_or_else(|| BenchError::Setup("the built-in world has no information map".into()))?;
    let coarse = content.occupancy.meta;
    let extent = |cells: u32| (f64::from(cells) * coarse.resolution / resolution).round() as u32;
    let meta = GridMeta {
        width: extent(coarse.width),
        height: extent(coarse.height),
        resolution,
        origin: coarse.origin,
    };
    let mut occupancy = Grid::filled(meta, -1i8);
    let mut info = Grid::filled(meta, 0u8);
    for y in 0..meta.height as usize {
        for x in 0..meta.width as usize {
            let (wx, wy) = cell_center(&meta, x, y);
            if let Some((cx, cy)) = world_to_cell(&coarse, wx, wy) {
                let i = cy * coarse.width as usize + cx;
                occupancy.cells[y * meta.width as usize + x] = content.occupancy.cells[i];
                info.cells[y * meta.width as usize + x] = information.cells[i];
            }
        }
    }
    let radius = content.robot_radius_m.unwrap_or(0.2);
    Ok((inflate(&occupancy, radius, 65), info))
}

/// A 30 × 51 m warehouse at 3 cm (1000 × 1700 cells): outer walls, rows of shelves 1 m
/// deep and 12 m long with 3 m aisles, a cross aisle; zones of interest on the racks
/// (80), the aisles beside them (40), a loading area (60), 10 elsewhere. Inflated by a
/// 0.25 m robot radius.
pub fn warehouse() -> (Grid<i8>, Grid<u8>) {
    warehouse_at(0.03)
}

/// The same warehouse at `resolution` metres.
pub fn warehouse_at(resolution: f64) -> (Grid<i8>, Grid<u8>) {
    let meta = GridMeta {
        width: (30.0 / resolution).round() as u32,
        height: (51.0 / resolution).round() as u32,
        resolution,
        origin: Origin::default(),
    };
    let mut occupancy = Grid::filled(meta, 0i8);
    let mut info = Grid::filled(meta, 10u8);
    let (w, h) = (meta.width as usize, meta.height as usize);
    for y in 0..h {
        for x in 0..w {
            let (mx, my) = cell_center(&meta, x, y);
            let wall = mx < 0.15 || my < 0.15 || mx > 29.85 || my > 50.85;
            // Shelf rows along x, every 4 m in y from 8 m, 12 m long on either side of
            // a 4 m cross aisle at x 13..17.
            let racks = (8.0..48.0).contains(&my);
            let row = racks && (my - 8.0) % 4.0 < 1.0;
            let along = (mx > 1.0 && mx < 13.0) || (mx > 17.0 && mx < 29.0);
            let shelf = row && along;
            let i = y * w + x;
            if wall || shelf {
                occupancy.cells[i] = 100;
            }
            if shelf {
                info.cells[i] = 80;
            } else if racks && along && (my - 8.0) % 4.0 < 2.0 {
                info.cells[i] = 40;
            } else if mx < 8.0 && my < 6.0 {
                info.cells[i] = 60;
            }
        }
    }
    (inflate(&occupancy, 0.25, 65), info)
}

/// The warehouse trip: from the loading area to the far end, across the racks.
pub const WAREHOUSE_START: [f64; 2] = [3.0, 3.0];
pub const WAREHOUSE_GOAL: [f64; 2] = [22.0, 15.0];

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The distinct information of a driven path on the reference world's cells.
fn reference_information(reference: &World, outcome: &PlanOutcome) -> f64 {
    let mut cells: Vec<Cell> = Vec::new();
    for p in &outcome.points {
        if let Some(c) = reference.cell_at(p[0], p[1]) {
            if cells.last() != Some(&c) {
                cells.push(c);
            }
        }
    }
    path_metrics(reference, &GaParams::default(), &cells).distinct_information
}

/// The paper's workload on `world`, `runs` seeds.
#[allow(clippy::too_many_arguments)]
fn row(
    family: &str,
    name: &str,
    (inflated, information): (&Grid<i8>, &Grid<u8>),
    planning_m: f64,
    trip: ([f64; 2], [f64; 2]),
    budget_s: f64,
    reference: &World,
    runs: usize,
) -> Result<ScalingRow, BenchError> {
    let started = Instant::now();
    let world = World::at_resolution(inflated, information, 0.25, planning_m).map_err(setup)?;
    let build_s = started.elapsed().as_secs_f64();
    let never = AtomicBool::new(false);
    let (mut seconds, mut info, mut eta, mut cells) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut within = 0;
    let mut cpu = Vec::new();
    for seed in 0..runs as u64 {
        let spec = PlanSpec::batch(trip.0, trip.1, budget_s, PlannerModel::Model1, 2000, seed);
        let started = Instant::now();
        let cpu_before = process_cpu_seconds();
        let outcome = plan(&world, &spec, &never, |_, _| {}).map_err(setup)?;
        seconds.push(started.elapsed().as_secs_f64());
        if let (Some(a), Some(b)) = (cpu_before, process_cpu_seconds()) {
            cpu.push(b - a);
        }
        info.push(reference_information(reference, &outcome));
        eta.push(outcome.t_eta_s);
        cells.push(outcome.cells.len() as f64);
        within += usize::from(outcome.within_budget);
    }
    Ok(ScalingRow {
        world: name.to_owned(),
        family: family.to_owned(),
        map_resolution_m: inflated.meta.resolution,
        map_cells: inflated.cells.len(),
        planning_resolution_m: world.meta.resolution,
        planning_cells: world.cell_count(),
        build_s,
        plan_s_median: median(&mut seconds),
        ratio_to_paper_scale: f64::NAN,
        plan_cpu_s_median: median(&mut cpu),
        cpu_ratio_to_paper_scale: f64::NAN,
        distinct_information_ref_median: median(&mut info),
        t_eta_s_median: median(&mut eta),
        budget_s,
        path_cells_median: median(&mut cells),
        within_budget: within,
        runs,
    })
}

fn layer(name: &str, meta: GridMeta, cells: Cells) -> Layer {
    Layer {
        name: name.to_owned(),
        version: 1,
        derived_from: None,
        meta,
        cells,
    }
}

/// The memory a planner's map cache takes holding the warehouse (the layers as they
/// arrive from the map server, and the planning world built from them), and after one
/// plan on it.
fn memory() -> Result<MemoryBench, BenchError> {
    let before = rss_mib().unwrap_or(f64::NAN);
    let mut cache = MapCache::new(4).planning_at(Some(PLANNING_M));
    let map_cells;
    {
        let (inflated, information) = warehouse();
        map_cells = inflated.cells.len();
        let meta = inflated.meta;
        cache.update(layer("inflated", meta, Cells::I8(inflated.cells)));
        cache.update(layer("information", meta, Cells::U8(information.cells)));
    }
    let (_, world) = cache
        .world(None)
        .ok_or_else(|| BenchError::Setup(format!("no world: {:?}", cache.last_error())))?;
    let cache_rss = rss_mib().unwrap_or(f64::NAN) - before;
    let spec = PlanSpec::batch(
        WAREHOUSE_START,
        WAREHOUSE_GOAL,
        86_400.0,
        PlannerModel::Shortest,
        1,
        0,
    );
    let never = AtomicBool::new(false);
    let floor = plan(&world, &spec, &never, |_, _| {}).map_err(setup)?;
    let spec = PlanSpec::batch(
        WAREHOUSE_START,
        WAREHOUSE_GOAL,
        2.0 * floor.t_eta_s,
        PlannerModel::Model1,
        2000,
        0,
    );
    plan(&world, &spec, &never, |_, _| {}).map_err(setup)?;
    let after = rss_mib().unwrap_or(f64::NAN) - before;
    drop(world);
    drop(cache);
    Ok(MemoryBench {
        map_cells,
        cache_rss_mib: cache_rss,
        after_plan_rss_mib: after,
        peak_rss_mib: peak_rss_mib(),
    })
}

/// Runs the bench (see the module doc); `progress` after each row (a world planned at
/// one resolution).
pub fn scaling(runs: usize, progress: Progress<'_>) -> Result<ScalingBench, BenchError> {
    // Two rows per resolution of the built-in world, three of the warehouse.
    let rows = 2 * RESOLUTIONS.len() + 3;
    let tick = |coarse: &[ScalingRow], native: &[ScalingRow]| {
        progress(Done::of("rows", "rows", coarse.len() + native.len(), rows));
    };
    tick(&[], &[]);
    let memory = memory()?;
    let reference = builtin_world()?;
    let never = AtomicBool::new(false);
    let floor = plan(
        &reference,
        &PlanSpec::batch(START, GOAL, 86_400.0, PlannerModel::Shortest, 1, 0),
        &never,
        |_, _| {},
    )
    .map_err(setup)?;
    let budget = 2.0 * floor.t_eta_s;
    let (mut coarse, mut native) = (Vec::new(), Vec::new());
    let builtin = "built-in";
    for resolution in RESOLUTIONS {
        let (inflated, information) = builtin_at(resolution)?;
        let name = format!("built-in at {resolution} m");
        let (trip, at) = ((START, GOAL), (&inflated, &information));
        coarse.push(row(
            builtin, &name, at, PLANNING_M, trip, budget, &reference, runs,
        )?);
        native.push(row(
            builtin, &name, at, resolution, trip, budget, &reference, runs,
        )?);
        tick(&coarse, &native);
    }
    let (inflated, information) = warehouse();
    // Its own yardstick: the warehouse's information at 0.2 m.
    let wh_reference = World::at_resolution(&inflated, &information, 0.25, 0.21).map_err(setup)?;
    let floor_spec = PlanSpec::batch(
        WAREHOUSE_START,
        WAREHOUSE_GOAL,
        86_400.0,
        PlannerModel::Shortest,
        1,
        0,
    );
    let wh_floor = plan(&wh_reference, &floor_spec, &never, |_, _| {}).map_err(setup)?;
    let wh_budget = 2.0 * wh_floor.t_eta_s;
    let trip = (WAREHOUSE_START, WAREHOUSE_GOAL);
    // The same warehouse drawn at 0.2 m: the family's paper-scale row.
    let (paper_inflated, paper_information) = warehouse_at(0.2);
    let wh = "warehouse";
    let (paper_map, fine_map) = (
        (&paper_inflated, &paper_information),
        (&inflated, &information),
    );
    let (at_02, at_003) = (
        "warehouse 30 x 51 m at 0.2 m",
        "warehouse 30 x 51 m at 0.03 m",
    );
    coarse.push(row(
        wh,
        at_02,
        paper_map,
        PLANNING_M,
        trip,
        wh_budget,
        &wh_reference,
        runs,
    )?);
    tick(&coarse, &native);
    coarse.push(row(
        wh,
        at_003,
        fine_map,
        PLANNING_M,
        trip,
        wh_budget,
        &wh_reference,
        runs,
    )?);
    tick(&coarse, &native);
    native.push(row(
        wh,
        at_003,
        fine_map,
        0.03,
        trip,
        wh_budget,
        &wh_reference,
        runs,
    )?);
    tick(&coarse, &native);
    for family in [builtin, wh] {
        let Some(paper) = coarse.iter().find(|r| r.family == family).cloned() else {
            continue;
        };
        for r in coarse
            .iter_mut()
            .chain(native.iter_mut())
            .filter(|r| r.family == family)
        {
            r.ratio_to_paper_scale = r.plan_s_median / paper.plan_s_median;
            r.cpu_ratio_to_paper_scale = r.plan_cpu_s_median / paper.plan_cpu_s_median;
        }
    }
    Ok(ScalingBench {
        planned_coarse: coarse,
        planned_at_map_resolution: native,
        memory,
        goal_ratio: 1.5,
        runs,
    })
}
