//! `roam reproduce planner`: paper 000's evaluation (§III) on the built-in world.
//!
//! The built-in world is shaped like the paper's Figs. 1 and 5: Goal 1 at (-2, 4) inside
//! a homogeneous zone of interest, Goal 2 at (6, -7) in a heterogeneous area, 0.2 m
//! cells, scores below 100, d = 3. For each goal, each t_plan / t_exec split of the
//! total time T (20/80, 40/60, 60/40) and each model (0, I, II), `runs` plans with seeds
//! 0.. are made from the start (-8, -8).
//!
//! Scaling t_plan: the paper's planner ran for 48–144 s; roam's runs 2000 generations in
//! under a second. roam keeps the paper's ratios but spends planning time as a share of
//! generations: t_plan = r · T buys `r · generations_per_t` generations (default 2500,
//! so 500 / 1000 / 1500, below Table I's 2000), which keeps every run reproducible bit
//! for bit. t_exec = (1 − r) · T with T = 100 s by default (the paper: 240 s for a world
//! whose shortest paths are longer; ours need about 30 s). Both are parameters.
//!
//! Initialization: every run plans with roam's default (via-point seeds, the
//! round-trip rule, the shortest path in the first population, walks finished at G,
//! issue 14, see `roam_planner::seeds` and `roam_planner::ga`) and with paper 000's own
//! (§II.A.1: random walks only, see `GaParams::random_walks_only`), on the same seeds,
//! and prints the two side by side ([`seeding`]): roam's seeding forces "within budget"
//! and "reached goal" to 100% (the shortest path is in every first population, elitism
//! keeps it, and W_2 + W_3 outweigh any reachable F1), the paper's does not.
//! [`ReproduceOptions::initializations`] may ask for one of them only.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use roam_map_server::map_file;
use roam_planner::plan::{plan, PlanSpec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;
use roam_world::legend::{framed, Entry, Frame};
use roam_world::render::{draw_marker, draw_path, render_map, INFORMATION, MARKER, OCCUPIED, PATH};
use roam_world::DEFAULT_MAX_CELLS;
use serde::Serialize;

use crate::progress::{Done, Progress};
use crate::ExperimentError;

/// The built-in world as the planner sees it (the planner service's inflation and
/// Table I's heuristic compression).
pub fn builtin_world() -> Result<World, ExperimentError> {
    let content = roam_map_server::map_file::builtin(DEFAULT_MAX_CELLS)
        .map_err(|e| ExperimentError::Setup(e.to_string()))?;
    let inflated = roam_world::layers::inflate(
        &content.occupancy,
        content.robot_radius_m.unwrap_or(0.2),
        65,
    );
    let information = content.information.ok_or_else(|| {
        ExperimentError::Setup("the built-in world has no information map".into())
    })?;
    World::new(&inflated, &information, 0.25).map_err(|e| ExperimentError::Setup(e.to_string()))
}

mod claims;
mod row;
mod seeding;
mod setup;

pub use crate::verdict::{Comparison, PaperFigure, Verdict};
pub use row::Row;
pub use seeding::SeedingRow;
pub use setup::{GOALS, MODELS, RATIOS, START};

/// How the GA's first population is built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Initialization {
    /// roam's default (`GaParams::default`).
    Roam,
    /// Paper 000 §II.A.1 to the letter (`GaParams::with_random_walks_only`).
    Paper,
}

impl Initialization {
    pub fn as_str(self) -> &'static str {
        match self {
            Initialization::Roam => "roam",
            Initialization::Paper => "paper",
        }
    }

    fn params(self, params: roam_planner::params::GaParams) -> roam_planner::params::GaParams {
        match self {
            Initialization::Roam => params,
            Initialization::Paper => params.with_random_walks_only(),
        }
    }
}

#[derive(Debug, Clone)]
pub struct ReproduceOptions {
    pub runs: usize,
    pub total_s: f64,
    pub generations_per_t: f64,
    pub out_dir: PathBuf,
    /// The initializations to run, in order; the first one's paths are drawn as
    /// `model{0,1,2}.png`, the others' as `<name>-model{0,1,2}.png`.
    pub initializations: Vec<Initialization>,
}

/// One initialization's rows and the paper's claims judged on them.
#[derive(Debug, Clone, Serialize)]
pub struct InitializationRun {
    pub initialization: Initialization,
    pub rows: Vec<Row>,
    pub comparisons: Vec<Comparison>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Reproduction {
    /// Each initialization asked for, in order.
    pub initializations: Vec<InitializationRun>,
    /// roam's and the paper's initialization side by side, when both ran.
    pub seeding: Vec<SeedingRow>,
    pub pictures: Vec<PathBuf>,
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}

/// Every configuration with every initialization asked for; `progress` after each plan
/// (one stage, `plans`, over all of them).
pub fn run(
    options: &ReproduceOptions,
    progress: Progress<'_>,
) -> Result<Reproduction, ExperimentError> {
    let world = builtin_world()?;
    let mut initializations = Vec::new();
    let mut pictures = Vec::new();
    let total =
        options.initializations.len() * GOALS.len() * RATIOS.len() * MODELS.len() * options.runs;
    let mut done = 0;
    let mut planned = || {
        done += 1;
        progress(Done::of("plans", "plans", done, total));
    };
    for (n, init) in options.initializations.iter().enumerate() {
        let (rows, paths) = run_one(&world, options, *init, &mut planned)?;
        let prefix = if n == 0 {
            String::new()
        } else {
            format!("{}-", init.as_str())
        };
        pictures.extend(draw(&world, &paths, &options.out_dir, &prefix, *init)?);
        initializations.push(InitializationRun {
            initialization: *init,
            comparisons: claims::compare(&rows),
            rows,
        });
    }
    let by = |which| {
        initializations
            .iter()
            .find(|r| r.initialization == which)
            .map(|r| r.rows.as_slice())
    };
    let seeding = match (by(Initialization::Roam), by(Initialization::Paper)) {
        (Some(roam), Some(paper)) => seeding::side_by_side(roam, paper),
        _ => Vec::new(),
    };
    Ok(Reproduction {
        initializations,
        seeding,
        pictures,
    })
}

/// A path to draw, with the model that planned it.
type Drawn = (PlannerModel, Vec<u32>);

/// Every configuration with one initialization; returns the rows and the paths drawn
/// (Goal 2, 40/60, seed 0).
fn run_one(
    world: &World,
    options: &ReproduceOptions,
    init: Initialization,
    planned: &mut dyn FnMut(),
) -> Result<(Vec<Row>, Vec<Drawn>), ExperimentError> {
    let never = AtomicBool::new(false);
    let mut rows = Vec::new();
    let mut pictures_paths: Vec<Drawn> = Vec::new();
    for (goal_name, goal) in GOALS {
        for (ratio_name, plan_share) in RATIOS {
            let t_exec_s = (1.0 - plan_share) * options.total_s;
            let generations = (plan_share * options.generations_per_t).round().max(1.0) as u32;
            for model in MODELS {
                let (mut u, mut d, mut info) = (Vec::new(), Vec::new(), Vec::new());
                let (mut within, mut reached) = (0usize, 0usize);
                for seed in 0..options.runs as u64 {
                    let mut spec = PlanSpec::batch(START, goal, t_exec_s, model, generations, seed);
                    spec.params = init.params(spec.params);
                    let outcome = plan(world, &spec, &never, |_, _| {}).map_err(|e| {
                        ExperimentError::Setup(format!(
                            "{} {goal_name} {ratio_name} {}: {e}",
                            init.as_str(),
                            model.as_str()
                        ))
                    })?;
                    u.push(outcome.metrics.u_ges);
                    d.push(outcome.metrics.density);
                    info.push(outcome.metrics.distinct_information);
                    planned();
                    within += usize::from(outcome.within_budget);
                    reached += usize::from(outcome.reaches_goal);
                    if seed == 0 && goal_name == "goal2" && ratio_name == "40/60" {
                        pictures_paths.push((model, outcome.path.clone()));
                    }
                }
                let runs = options.runs.max(1) as f64;
                rows.push(Row {
                    goal: goal_name.to_owned(),
                    ratio: ratio_name.to_owned(),
                    model: model.as_str().to_owned(),
                    u_ges_mean: mean(&u),
                    u_ges_median: median(&mut u),
                    d_median: median(&mut d),
                    distinct_information_median: median(&mut info),
                    within_budget: within as f64 / runs,
                    reached_goal: reached as f64 / runs,
                    generations,
                    t_exec_s,
                });
            }
        }
    }
    Ok((rows, pictures_paths))
}

/// The title, legend and scale bar of a model's picture.
pub fn picture_frame(model: PlannerModel, init: Initialization, pixels_per_metre: f64) -> Frame {
    Frame {
        title: vec![
            format!(
                "paper 000 sec. III: {}, {} initialization",
                model.as_str(),
                init.as_str()
            ),
            "goal 2, t_plan/t_exec 40/60, seed 0".into(),
        ],
        legend: vec![
            Entry::fill(INFORMATION, "zone of interest (darker: more)"),
            Entry::fill(OCCUPIED, "wall"),
            Entry::line(PATH, "the planned path"),
            Entry::fill(MARKER, "start and goal"),
        ],
        text_scale: 2,
        pixels_per_metre: Some(pixels_per_metre),
    }
}

fn draw(
    world: &World,
    paths: &[Drawn],
    out_dir: &Path,
    prefix: &str,
    init: Initialization,
) -> Result<Vec<PathBuf>, ExperimentError> {
    let content =
        map_file::builtin(DEFAULT_MAX_CELLS).map_err(|e| ExperimentError::Setup(e.to_string()))?;
    let info = content.information.as_ref();
    std::fs::create_dir_all(out_dir)
        .map_err(|e| ExperimentError::Setup(format!("{}: {e}", out_dir.display())))?;
    let scale = 8;
    let mut written = Vec::new();
    for (model, path) in paths {
        let mut image = render_map(&content.occupancy, info, scale);
        let cells = world.grid_cells(path);
        draw_path(&mut image, world.meta.height, &cells, scale, PATH);
        for end in [cells.first(), cells.last()].into_iter().flatten() {
            draw_marker(&mut image, world.meta.height, *end, scale, MARKER);
        }
        let file = out_dir.join(format!("{prefix}{}.png", model.as_str()));
        let per_metre = f64::from(scale) / content.occupancy.meta.resolution;
        framed(&image, &picture_frame(*model, init, per_metre))
            .save(&file)
            .map_err(|e| ExperimentError::Setup(format!("{}: {e}", file.display())))?;
        written.push(file);
    }
    Ok(written)
}

impl std::fmt::Display for Reproduction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for run in &self.initializations {
            write!(f, "{run}")?;
            writeln!(f)?;
        }
        if !self.seeding.is_empty() {
            write!(f, "{}", seeding::Table(&self.seeding))?;
        }
        for p in &self.pictures {
            writeln!(f, "picture: {}", p.display())?;
        }
        Ok(())
    }
}

impl std::fmt::Display for InitializationRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "paper 000 §III on the built-in world (start (-8, -8)); t_plan spent as generations; {} initialization",
            self.initialization.as_str()
        )?;
        writeln!(
            f,
            "{:<6} {:<6} {:<7} {:>6} {:>9} {:>9} {:>7} {:>9} {:>7} {:>7}",
            "goal",
            "ratio",
            "model",
            "gens",
            "U median",
            "U mean",
            "D med",
            "I seen",
            "budget",
            "goal"
        )?;
        for r in &self.rows {
            writeln!(
                f,
                "{:<6} {:<6} {:<7} {:>6} {:>9.0} {:>9.0} {:>7.1} {:>9.0} {:>6.0}% {:>6.0}%",
                r.goal,
                r.ratio,
                r.model,
                r.generations,
                r.u_ges_median,
                r.u_ges_mean,
                r.d_median,
                r.distinct_information_median,
                r.within_budget * 100.0,
                r.reached_goal * 100.0
            )?;
        }
        writeln!(f, "claims, ours next to the paper's:")?;
        for c in &self.comparisons {
            writeln!(
                f,
                "  {:<70} paper {:<40} ours {:<18} {}",
                c.claim,
                c.paper,
                c.ours,
                c.verdict.as_str()
            )?;
        }
        Ok(())
    }
}
