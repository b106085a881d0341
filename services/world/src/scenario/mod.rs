//! roam's scenario file: the map (a ROS map or shapes on an empty grid), the robot
//! radius for inflation, the zones of interest that make the information map, named
//! places (start, goals, tasks), and the sim world's sections: anchors, sensing, motion,
//! robots, scripted blocks, random walkers, mission waypoints and the sim clock.
//!
//! A scenario is YAML; paths inside it are relative to the scenario file. The map server
//! reads the map and information sections; the sim world (`roam-sim`) reads the rest.
//! Every sim section is optional and has defaults (paper 002 §4's parameters). Unknown
//! fields are refused so a typo is caught, and every value is checked here, at load
//! time, with an error that names the file and the field.
//!
//! ```yaml
//! name: downtime-20x20
//! map:
//!   grid:                      # or  ros: ../maps/depot.yaml
//!     size_m: [20.0, 20.0]
//!     resolution: 0.2
//!     origin: [-10.0, -10.0]
//!     border_walls: true
//!     obstacles:
//!       - rect: [-6.0, -2.0, -5.6, 6.0]     # x0, y0, x1, y1 in metres
//!       - circle: [3.0, 3.0, 0.8]           # cx, cy, radius in metres
//! robot_radius_m: 0.2
//! information:
//!   default_score: 0
//!   zones:
//!     - { name: lab, score: 80, rect: [-9.0, 5.0, -3.0, 9.0] }
//! places:
//!   - { name: start, at: [0.0, 0.0] }
//! # The sim world's sections (all optional):
//! anchors:                     # TOA beacons, metres; may stand on walls
//!   - { name: a1, at: [-9.5, -9.5] }
//! sensing: { range_m: 30.0, sigma_toa_m: 0.10, d0_m: 15.0, k: 2.0, observation_radius_m: 5.0 }
//! motion: { step_mu: 0.2, sigma_tr_m: 0.01, max_speed_m_per_step: 0.2 }   # model: point
//! # or a robot that pays for turning (roam's unicycle):
//! # motion: { model: { unicycle: { v_max_m_per_s: 0.5, w_max_rad_per_s: 1.0 } } }
//! robots:                      # start positions, metres, on free cells
//!   - { name: r1, at: [-8.0, -8.0] }   # heading_rad: 0.0 (the unicycle's, default 0)
//! blocks:                      # scripted moving obstacles
//!   - { name: b1, size_cells: [2, 2], period_steps: 7, path: [[1.0, 1.0], [3.0, 1.0]] }
//! walkers:                     # random walkers
//!   - { name: w1, at: [2.0, -5.0], size_m: 0.4, step_m: 0.2, every_steps: 3 }
//! changes:                     # objects that appear in a zone and vanish (changes.rs)
//!   - { name: dock, rect: [1.0, 1.0, 5.0, 3.0], size_m: [1.2, 1.0], appear_per_hour: 6.0,
//!       mean_stay_s: 600.0, max_present: 2 }
//! waypoints:                   # a mission, in order
//!   - { name: A, at: [-8.0, -8.0] }
//! time: { step_s: 0.4 }
//! ```

use std::path::{Path, PathBuf};

use roam_proto::excerpt::file_parse_reason;

use crate::grid::{Grid, DEFAULT_MAX_CELLS};
use crate::load_dirs::{Access, LoadRefused};
use crate::ros_map::{self, RosMapError};

mod build;
pub mod changes;
mod field_issue;
mod file;
mod motion;
mod sim_check;
mod sim_sections;

use build::{build_grid, build_information};
pub use field_issue::FieldIssue;
pub use file::{GridSpec, InformationSpec, MapSource, Place, ScenarioFile, Shape, Zone};
pub use motion::*;
use sim_check::validate_sim;
pub use sim_sections::*;

/// A scenario with its grids built.
#[derive(Debug, Clone)]
pub struct Scenario {
    pub file: ScenarioFile,
    pub occupancy: Grid<i8>,
    pub information: Grid<u8>,
}

/// Why a scenario could not be used. Each variant names the file and the field.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    #[error("scenario file {path} does not exist")]
    Missing { path: PathBuf },
    #[error("cannot read scenario file {path}: {reason}")]
    Io { path: PathBuf, reason: String },
    #[error("scenario file {path}: {reason}")]
    Invalid { path: PathBuf, reason: String },
    #[error("scenario file {path}, field {field}: {reason}")]
    Field {
        path: PathBuf,
        field: String,
        reason: String,
    },
    #[error("scenario file {path}: {source}")]
    Map { path: PathBuf, source: RosMapError },
    #[error(transparent)]
    Refused(#[from] LoadRefused),
}

/// The embedded default world: a paper-000-like 20 × 20 m downtime world
/// (`config/scenarios/downtime.yaml`), used wherever no map or scenario is given.
pub const BUILTIN: &str = include_str!("../../../../config/scenarios/downtime.yaml");

/// The name the built-in world goes by in messages.
pub const BUILTIN_NAME: &str = "<built-in downtime world>";

/// The built-in world, parsed.
pub fn builtin() -> Result<Scenario, ScenarioError> {
    parse(Path::new(BUILTIN_NAME), BUILTIN, DEFAULT_MAX_CELLS)
}

/// The world every service of a stack is given: the scenario at `path` (or a ROS map,
/// as a scenario of the map alone), or the built-in world without one; with the name
/// to show it by. Grids are bounded by [`DEFAULT_MAX_CELLS`], the map server's default.
pub fn load_or_builtin(path: Option<&Path>) -> Result<(String, Scenario), ScenarioError> {
    match path {
        Some(p) => Ok((p.display().to_string(), load_any(p, DEFAULT_MAX_CELLS)?)),
        None => Ok((BUILTIN_NAME.to_owned(), builtin()?)),
    }
}

/// Reads a scenario file and builds its grids.
pub fn load(path: &Path, max_cells: u64) -> Result<Scenario, ScenarioError> {
    load_with(path, max_cells, Access::Anywhere)
}

/// Reads a scenario, or a ROS `map.yaml` (it has an `image:` key) as a scenario of that
/// map alone, named after the file: no places, anchors, robots or other sim sections.
/// So every service can be given the same file, whichever kind it is.
pub fn load_any(path: &Path, max_cells: u64) -> Result<Scenario, ScenarioError> {
    let is_ros = crate::ros_map::read_bounded_text(path)
        .ok()
        .and_then(|text| serde_yaml_ng::from_str::<serde_yaml_ng::Value>(&text).ok())
        .is_some_and(|v| v.get("image").is_some());
    if !is_ros {
        return load(path, max_cells);
    }
    let stem = path
        .file_stem()
        .map_or_else(|| "map".to_owned(), |s| s.to_string_lossy().into_owned());
    let file = path.file_name().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let text = serde_yaml_ng::to_string(&serde_yaml_ng::Value::Mapping(
        [
            ("name".into(), stem.into()),
            (
                "map".into(),
                serde_yaml_ng::Value::Mapping([("ros".into(), file.into())].into_iter().collect()),
            ),
        ]
        .into_iter()
        .collect(),
    ))
    .map_err(|e| ScenarioError::Invalid {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    parse(path, &text, max_cells)
}

/// The observation radius of a scenario that does not set one: `radius_m` (the sim's
/// [`DEFAULT_OBSERVATION_RADIUS_M`], or a site's own default) cut to the limit in cells
/// on a fine map (3.84 m at 3 cm), so a Nav2 map at any resolution loads; a radius the
/// user wrote is checked against the limit instead, naming the field.
pub fn fitted_observation_radius_m(radius_m: f64, resolution: f64) -> f64 {
    radius_m.min(MAX_OBSERVATION_RADIUS_CELLS * resolution)
}

/// Whether the scenario's text sets `sensing.observation_radius_m` itself.
fn sets_observation_radius(text: &str) -> bool {
    serde_yaml_ng::from_str::<serde_yaml_ng::Value>(text)
        .ok()
        .and_then(|v| {
            v.get("sensing")
                .map(|s| s.get("observation_radius_m").is_some())
        })
        .unwrap_or(false)
}

impl Scenario {
    /// Whether the scenario has a sim world (robots or anchors), or is a map alone.
    pub fn has_sim_world(&self) -> bool {
        !self.file.robots.is_empty() || !self.file.anchors.is_empty()
    }
}

/// [`load`], following the files the scenario names only where `access` allows (a load
/// from the wire: inside the load directories).
pub fn load_with(
    path: &Path,
    max_cells: u64,
    access: Access<'_>,
) -> Result<Scenario, ScenarioError> {
    let text = crate::ros_map::read_bounded_text(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            ScenarioError::Missing {
                path: path.to_owned(),
            }
        } else {
            ScenarioError::Io {
                path: path.to_owned(),
                reason: e.to_string(),
            }
        }
    })?;
    parse_with(path, &text, max_cells, access)
}

/// Parses scenario text; `path` names the file in errors and anchors relative paths.
pub fn parse(path: &Path, text: &str, max_cells: u64) -> Result<Scenario, ScenarioError> {
    parse_with(path, text, max_cells, Access::Anywhere)
}

/// [`parse`], following the files the scenario names only where `access` allows. Parse
/// errors give the position and what was expected, never the file's content.
pub fn parse_with(
    path: &Path,
    text: &str,
    max_cells: u64,
    access: Access<'_>,
) -> Result<Scenario, ScenarioError> {
    let mut file: ScenarioFile =
        serde_yaml_ng::from_str(text).map_err(|e| ScenarioError::Invalid {
            path: path.to_owned(),
            reason: file_parse_reason(&e.to_string()),
        })?;
    let field = |field: &str, reason: String| ScenarioError::Field {
        path: path.to_owned(),
        field: field.to_owned(),
        reason,
    };
    let base = path.parent().unwrap_or_else(|| Path::new("."));
    let occupancy = match &file.map {
        MapSource::Ros(map_yaml) => {
            ros_map::load_with(&access.check(&base.join(map_yaml))?, max_cells, access)
                .map_err(|source| ScenarioError::Map {
                    path: path.to_owned(),
                    source,
                })?
                .grid
        }
        MapSource::Grid(spec) => {
            build_grid(spec, max_cells).map_err(|reason| field("map.grid", reason))?
        }
    };
    if !sets_observation_radius(text) {
        file.sensing.observation_radius_m =
            fitted_observation_radius_m(DEFAULT_OBSERVATION_RADIUS_M, occupancy.meta.resolution);
    }
    if let Some(r) = file.robot_radius_m {
        if !(r.is_finite() && r >= 0.0) {
            return Err(field(
                "robot_radius_m",
                format!("must be a non-negative number of metres, got {r}"),
            ));
        }
    }
    let information = match &file.information {
        None => Grid::filled(occupancy.meta, 0),
        Some(spec) => build_information(spec, &occupancy.meta, base, max_cells, access)
            .map_err(|(f, reason)| field(&f, reason))?,
    };
    for (i, place) in file.places.iter().enumerate() {
        let [x, y] = place.at;
        if crate::grid::world_to_cell(&occupancy.meta, x, y).is_none() {
            return Err(field(
                &format!("places[{i}].at"),
                format!("place '{}' at ({x}, {y}) is outside the map", place.name),
            ));
        }
    }
    validate_sim(&file, &occupancy).map_err(|i| field(&i.field, i.reason))?;
    Ok(Scenario {
        file,
        occupancy,
        information,
    })
}
