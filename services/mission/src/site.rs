//! A site: the world one robot's day runs in and the day's tasks. Either the built-in
//! day ([`Site::builtin_day`]: `config/scenarios/day.yaml` and [`tasks::day`]) or a
//! user's own: a Nav2 map (`map.yaml` and its image) and a day file
//! ([`Site::load`]), what `roam demo --map … --tasks …` and `roam reproduce mission
//! --days N --map … --tasks …` run.
//!
//! ```yaml
//! # config/days/depot.yaml: a day on Nav2's depot map (config/maps/depot.yaml)
//! robot: { at: [3.0, 8.0] }          # where the robot starts (name "robot", heading 0)
//! tasks:                             # the day's tasks, in order (roam_mission::tasks)
//!   - { name: loading, at: [3.0, 2.5], start_s: 70, duration_s: 5 }
//!   - { name: racks, at: [13.0, 8.0], start_s: 160 }
//! # Optional, each written as in a scenario file (services/world/README.md):
//! robot_radius_m: 0.25               # default 0.2
//! information: { default_score: 10, zones: [ { name: racks, score: 80, rect: [...] } ] }
//! anchors: [ { name: a1, at: [0.5, 1.0] } ]
//! sensing: { range_m: 30.0 }
//! blocks: [...]                      # moving things; also walkers, changes, motion
//! ```
//!
//! **What a day file leaves out** takes a stated default:
//!
//! - `information`: every cell scores [`DEFAULT_SCORE`] (curiosity then goes for
//!   ground not yet seen, uniformly).
//! - `sensing`: the scenario's defaults for what it leaves out (paper 002's sensor, 30
//!   m of range), but the observation radius: the day world's,
//!   [`DEFAULT_OBSERVATION_RADIUS_M`], cut to what the sim's limit allows at the map's
//!   resolution ([`scenario::MAX_OBSERVATION_RADIUS_CELLS`] cells), so that any Nav2 map boots.
//! - `anchors`: placed by [`lattice_anchors`], a square lattice over the map's free
//!   cells whose spacing puts every point within range of the four corners of its
//!   lattice square. Whatever the anchors, the free cells with fewer than three in range
//!   (no TOA fix, paper 002 §2) are counted and named in a warning
//!   ([`Site::warnings`]).
//!
//! **What is refused** when the files are loaded, naming the field and the limit: a
//! day file that does not parse or has unknown fields; a map that does not load or has
//! no free cell; anchors, places or the robot off the map (the scenario's own checks);
//! tasks in walls, unreachable in time from the task before or overlapping
//! ([`crate::day_check`], with Table I's time model as `roam mission` checks a day).

use std::path::{Path, PathBuf};

use roam_planner::world::World;
use roam_world::grid::{cell_center, Grid, DEFAULT_MAX_CELLS};
use roam_world::layers::inflate;
use roam_world::ros_map;
use roam_world::scenario::{self, Scenario};
use serde::Deserialize;
use serde_yaml_ng::{Mapping, Value};

use crate::calibration::TimeModel;
use crate::day_check::check_day;
use crate::tasks::{self, Task, TaskError, DAY_SCENARIO};

/// The built-in day's name in reports.
pub const BUILTIN_DAY: &str = "built-in day";
/// The information score of every cell when a day file gives no `information`.
pub const DEFAULT_SCORE: u8 = 10;
/// The observation radius when a day file gives none (the day world's), metres.
pub const DEFAULT_OBSERVATION_RADIUS_M: f64 = 3.0;
/// The robot's radius when a day file gives none (the day world's), metres.
pub const DEFAULT_ROBOT_RADIUS_M: f64 = 0.2;
/// The most anchors the lattice rule places (a very large map gets a wider lattice).
pub const MAX_LATTICE_ANCHORS: usize = 256;
/// How many uncovered cells a warning names by position.
const NAMED_UNCOVERED: usize = 3;
/// The inflated map's occupied value (the map server's `inflated` layer).
pub const INFLATED_COST: i8 = 65;
/// Model II's heuristic compression the planner's map cache cuts blocks for (Table I).
pub const HEURISTIC_COMPRESSION: f64 = 0.25;

/// A day file as written (module doc).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DayFile {
    pub robot: DayRobot,
    pub tasks: Vec<Task>,
    #[serde(default)]
    pub robot_radius_m: Option<f64>,
    /// The scenario sections a day file may carry, passed to the scenario as written
    /// and checked there.
    #[serde(default)]
    pub information: Option<Value>,
    #[serde(default)]
    pub anchors: Option<Value>,
    #[serde(default)]
    pub sensing: Option<Value>,
    #[serde(default)]
    pub motion: Option<Value>,
    #[serde(default)]
    pub blocks: Option<Value>,
    #[serde(default)]
    pub walkers: Option<Value>,
    #[serde(default)]
    pub changes: Option<Value>,
}

/// The day's robot: where it starts.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DayRobot {
    #[serde(default = "default_robot")]
    pub name: String,
    pub at: [f64; 2],
    #[serde(default)]
    pub heading_rad: f64,
}

fn default_robot() -> String {
    "robot".into()
}

/// Why a site is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SiteError {
    #[error("cannot read {path}: {reason}")]
    Read { path: PathBuf, reason: String },
    #[error("{path}: {reason}")]
    DayFile { path: PathBuf, reason: String },
    /// The scenario made of the map and the day file is refused (a field of the day
    /// file or the map itself).
    #[error("{0}")]
    Scenario(String),
    #[error("the map {path} has no free cell: a robot has nowhere to be")]
    NoFreeCells { path: PathBuf },
    #[error("{path}: {error}")]
    Tasks { path: PathBuf, error: TaskError },
}

/// A world and one robot's day in it.
#[derive(Debug, Clone, PartialEq)]
pub struct Site {
    /// What the site is called in reports (the day file's stem, or [`BUILTIN_DAY`]).
    pub name: String,
    /// The scenario every service loads: for a user's site, the map by its absolute
    /// path, the day file's sections, the robot and the anchors.
    pub scenario_yaml: String,
    /// The robot the day drives.
    pub robot: String,
    pub tasks: Vec<Task>,
    /// What the defaults could not give: free cells without a fix.
    pub warnings: Vec<String>,
}

impl Site {
    /// The built-in day: `config/scenarios/day.yaml` and [`tasks::day`].
    pub fn builtin_day() -> Site {
        Site {
            name: BUILTIN_DAY.into(),
            scenario_yaml: DAY_SCENARIO.to_owned(),
            robot: "robot".into(),
            tasks: tasks::day(),
            warnings: Vec::new(),
        }
    }

    /// The site's scenario, parsed (the path names it in errors).
    pub fn scenario(&self) -> Result<Scenario, SiteError> {
        parse(&self.scenario_yaml, &self.name)
    }

    /// A user's site: a ROS map (`map.yaml`) and a day file, checked as the module doc
    /// says.
    pub fn load(map: &Path, day_file: &Path) -> Result<Site, SiteError> {
        let text = std::fs::read_to_string(day_file).map_err(|e| SiteError::Read {
            path: day_file.to_owned(),
            reason: e.to_string(),
        })?;
        let map = std::path::absolute(map).map_err(|e| SiteError::Read {
            path: map.to_owned(),
            reason: e.to_string(),
        })?;
        let name = day_file
            .file_stem()
            .map_or("site".into(), |s| s.to_string_lossy().into_owned());
        Site::from_text(&map, &text, &name).map_err(|e| match e {
            SiteError::DayFile { reason, .. } => SiteError::DayFile {
                path: day_file.to_owned(),
                reason,
            },
            SiteError::Tasks { error, .. } => SiteError::Tasks {
                path: day_file.to_owned(),
                error,
            },
            other => other,
        })
    }

    /// [`Site::load`] on a day file's text; `map` is the ROS map's path as the
    /// scenario will name it.
    pub fn from_text(map: &Path, text: &str, name: &str) -> Result<Site, SiteError> {
        let file: DayFile = serde_yaml_ng::from_str(text).map_err(|e| SiteError::DayFile {
            path: PathBuf::from(name),
            reason: e.to_string(),
        })?;
        let occupancy = ros_map::load(map, DEFAULT_MAX_CELLS)
            .map_err(|e| SiteError::Scenario(e.to_string()))?
            .grid;
        if !occupancy.cells.iter().any(|&v| is_free(v)) {
            return Err(SiteError::NoFreeCells {
                path: map.to_owned(),
            });
        }
        let mut yaml = scenario_mapping(map, &file, name);
        // The observation radius, when the file does not give one, fits the map's
        // resolution: a check never names a field the user did not write.
        let mut sensing = match &file.sensing {
            Some(Value::Mapping(m)) => m.clone(),
            Some(_) => {
                return Err(SiteError::DayFile {
                    path: PathBuf::from(name),
                    reason: "sensing: give a mapping, e.g. { range_m: 30.0 }".into(),
                })
            }
            None => Mapping::new(),
        };
        if !sensing.contains_key("observation_radius_m") {
            let radius = scenario::fitted_observation_radius_m(
                DEFAULT_OBSERVATION_RADIUS_M,
                occupancy.meta.resolution,
            );
            sensing.insert("observation_radius_m".into(), radius.into());
        }
        yaml.insert("sensing".into(), Value::Mapping(sensing));
        if file.anchors.is_none() {
            let range = parse(&to_yaml(&yaml)?, name)?.file.sensing.range_m;
            let anchors: Vec<Value> = lattice_anchors(&occupancy, range)
                .into_iter()
                .enumerate()
                .map(|(i, [x, y])| {
                    let mut a = Mapping::new();
                    a.insert("name".into(), format!("lattice-{i}").into());
                    a.insert("at".into(), Value::Sequence(vec![x.into(), y.into()]));
                    Value::Mapping(a)
                })
                .collect();
            yaml.insert("anchors".into(), Value::Sequence(anchors));
        }
        let scenario_yaml = to_yaml(&yaml)?;
        let scenario = parse(&scenario_yaml, name)?;
        let planning = planning_world(&scenario)?;
        check_day(
            &file.tasks,
            &planning,
            TimeModel::table_i(),
            Some(file.robot.at),
        )
        .map_err(|error| SiteError::Tasks {
            path: PathBuf::from(name),
            error,
        })?;
        let anchors: Vec<[f64; 2]> = scenario.file.anchors.iter().map(|a| a.at).collect();
        let warnings =
            uncovered_warning(&scenario.occupancy, &anchors, scenario.file.sensing.range_m)
                .into_iter()
                .collect();
        Ok(Site {
            name: name.to_owned(),
            scenario_yaml,
            robot: file.robot.name,
            tasks: file.tasks,
            warnings,
        })
    }
}

/// The planner's grid for a scenario as the planner service builds it (inflated by the
/// robot's radius, the static information map), without the PEB field.
pub fn planning_world(scenario: &Scenario) -> Result<World, SiteError> {
    World::new(
        &inflated_map(scenario),
        &scenario.information,
        HEURISTIC_COMPRESSION,
    )
    .map_err(|e| SiteError::Scenario(e.to_string()))
}

/// The scenario's map inflated by the robot's radius, as the map server's `inflated`
/// layer.
pub fn inflated_map(scenario: &Scenario) -> Grid<i8> {
    inflate(
        &scenario.occupancy,
        scenario
            .file
            .robot_radius_m
            .unwrap_or(DEFAULT_ROBOT_RADIUS_M),
        INFLATED_COST,
    )
}

/// A free cell of a ROS occupancy grid (0 free … 100 occupied, −1 unknown), as the map
/// server thresholds it.
fn is_free(v: i8) -> bool {
    (0..50).contains(&v)
}

fn parse(yaml: &str, name: &str) -> Result<Scenario, SiteError> {
    scenario::parse(Path::new(&format!("{name}.yaml")), yaml, DEFAULT_MAX_CELLS)
        .map_err(|e| SiteError::Scenario(e.to_string()))
}

fn to_yaml(mapping: &Mapping) -> Result<String, SiteError> {
    serde_yaml_ng::to_string(mapping).map_err(|e| SiteError::Scenario(e.to_string()))
}

/// The scenario of a day file on a map, without the defaults that need the map.
fn scenario_mapping(map: &Path, file: &DayFile, name: &str) -> Mapping {
    let mut yaml = Mapping::new();
    yaml.insert("name".into(), name.into());
    yaml.insert(
        "description".into(),
        format!("{name}: a day on {}", map.display()).into(),
    );
    let mut source = Mapping::new();
    source.insert("ros".into(), map.to_string_lossy().into_owned().into());
    yaml.insert("map".into(), Value::Mapping(source));
    yaml.insert(
        "robot_radius_m".into(),
        file.robot_radius_m.unwrap_or(DEFAULT_ROBOT_RADIUS_M).into(),
    );
    let information = file.information.clone().unwrap_or_else(|| {
        let mut info = Mapping::new();
        info.insert("default_score".into(), u64::from(DEFAULT_SCORE).into());
        Value::Mapping(info)
    });
    yaml.insert("information".into(), information);
    let point = |at: [f64; 2]| Value::Sequence(vec![at[0].into(), at[1].into()]);
    let mut places = vec![place("start", point(file.robot.at))];
    for t in &file.tasks {
        if !places
            .iter()
            .any(|p| p.get("name") == Some(&Value::from(t.name.clone())))
        {
            places.push(place(&t.name, point(t.at)));
        }
    }
    yaml.insert(
        "places".into(),
        Value::Sequence(places.into_iter().map(Value::Mapping).collect()),
    );
    let mut robot = place(&file.robot.name, point(file.robot.at));
    robot.insert("heading_rad".into(), file.robot.heading_rad.into());
    yaml.insert(
        "robots".into(),
        Value::Sequence(vec![Value::Mapping(robot)]),
    );
    for (key, value) in [
        ("anchors", &file.anchors),
        ("sensing", &file.sensing),
        ("motion", &file.motion),
        ("blocks", &file.blocks),
        ("walkers", &file.walkers),
        ("changes", &file.changes),
    ] {
        if let Some(v) = value {
            yaml.insert(key.into(), v.clone());
        }
    }
    yaml
}

fn place(name: &str, at: Value) -> Mapping {
    let mut m = Mapping::new();
    m.insert("name".into(), name.into());
    m.insert("at".into(), at);
    m
}

/// **The anchor rule** (roam's; the papers place anchors by hand): a square lattice
/// over the bounding box of the map's free cells, corners included, with spacing
/// `0.7 · range_m`, so the four corners of the lattice square around any point are
/// within `0.7·√2 ≈ 0.99` of the range: every free cell hears at least four anchors
/// (three fix a position, paper 002 §2). Anchors may stand on walls, as in a scenario.
/// A map so large that the lattice would pass [`MAX_LATTICE_ANCHORS`] gets a wider
/// spacing, and the warning names the cells it leaves without a fix.
pub fn lattice_anchors(occupancy: &Grid<i8>, range_m: f64) -> Vec<[f64; 2]> {
    let meta = occupancy.meta;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for y in 0..occupancy.height() {
        for x in 0..occupancy.width() {
            if occupancy.get(x, y).is_some_and(is_free) {
                let (cx, cy) = cell_center(&meta, x, y);
                lo = [lo[0].min(cx), lo[1].min(cy)];
                hi = [hi[0].max(cx), hi[1].max(cy)];
            }
        }
    }
    if !(lo[0].is_finite() && range_m.is_finite() && range_m > 0.0) {
        return Vec::new();
    }
    let size = [hi[0] - lo[0], hi[1] - lo[1]];
    let mut spacing = 0.7 * range_m;
    let count = |s: f64| {
        let n = |extent: f64| (extent / s).ceil().max(1.0) as usize + 1;
        (n(size[0]), n(size[1]))
    };
    while {
        let (nx, ny) = count(spacing);
        nx * ny > MAX_LATTICE_ANCHORS
    } {
        spacing *= 1.25;
    }
    let (nx, ny) = count(spacing);
    let step = |extent: f64, n: usize| extent / (n - 1) as f64;
    let (sx, sy) = (step(size[0], nx), step(size[1], ny));
    let mut anchors = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            anchors.push([lo[0] + sx * i as f64, lo[1] + sy * j as f64]);
        }
    }
    anchors
}

/// How many free cells hear fewer than three anchors within `range_m`, with the first
/// few named; `None` when every free cell has a fix.
pub fn uncovered_warning(
    occupancy: &Grid<i8>,
    anchors: &[[f64; 2]],
    range_m: f64,
) -> Option<String> {
    let meta = occupancy.meta;
    let (mut count, mut named) = (0usize, Vec::new());
    for y in 0..occupancy.height() {
        for x in 0..occupancy.width() {
            if !occupancy.get(x, y).is_some_and(is_free) {
                continue;
            }
            let (cx, cy) = cell_center(&meta, x, y);
            let heard = anchors
                .iter()
                .filter(|a| (a[0] - cx).hypot(a[1] - cy) <= range_m)
                .count();
            if heard < 3 {
                count += 1;
                if named.len() < NAMED_UNCOVERED {
                    named.push(format!("({cx:.2}, {cy:.2}) hears {heard}"));
                }
            }
        }
    }
    (count > 0).then(|| {
        format!(
            "{count} free cells hear fewer than three anchors within {range_m} m and have no fix there (e.g. {}); add anchors near them or leave them out of the day",
            named.join(", ")
        )
    })
}

#[cfg(test)]
mod tests;
