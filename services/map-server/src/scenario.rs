//! roam's scenario file, the parts the map server reads: the map (a ROS map or shapes
//! on an empty grid), the robot radius for inflation, the zones of interest that make
//! the information map, and named places (start, goals, tasks).
//!
//! A scenario is YAML; paths inside it are relative to the scenario file. The sim world
//! adds its own sections (anchors, robots, blocks); every field is documented in the
//! README's "Scenario files" section. Unknown fields are refused so a typo is caught.
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
//! ```

use std::path::{Path, PathBuf};

use roam_proto::map::{GridMeta, Origin};
use serde::Deserialize;

use crate::grid::{cell_center, occupancy, Grid};
use crate::ros_map::{self, RosMapError};

/// A scenario file's map-server sections.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    pub name: String,
    #[serde(default)]
    pub description: Option<String>,
    /// Enums are written as one-key maps (`grid: {...}`, `rect: [...]`), not YAML tags.
    #[serde(with = "serde_yaml_ng::with::singleton_map_recursive")]
    pub map: MapSource,
    /// Robot radius for the inflated layer, metres.
    #[serde(default)]
    pub robot_radius_m: Option<f64>,
    #[serde(default)]
    pub information: Option<InformationSpec>,
    #[serde(default)]
    pub places: Vec<Place>,
}

/// Where the occupancy grid comes from.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum MapSource {
    /// A ROS `map.yaml`, relative to the scenario file.
    Ros(PathBuf),
    /// An empty grid with walls and shapes.
    Grid(GridSpec),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Width and height in metres.
    pub size_m: [f64; 2],
    /// Metres per cell.
    pub resolution: f64,
    /// World position of the grid's lower-left corner, metres.
    #[serde(default)]
    pub origin: [f64; 2],
    /// Occupy the outermost ring of cells.
    #[serde(default)]
    pub border_walls: bool,
    #[serde(default)]
    pub obstacles: Vec<Shape>,
}

/// A shape in world coordinates (metres).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum Shape {
    /// `[x0, y0, x1, y1]`, corners in any order.
    Rect([f64; 4]),
    /// `[cx, cy, radius]`.
    Circle([f64; 3]),
}

impl Shape {
    /// Whether the world point is inside the shape (edges included).
    pub fn contains(&self, x: f64, y: f64) -> bool {
        match *self {
            Shape::Rect([x0, y0, x1, y1]) => {
                x >= x0.min(x1) && x <= x0.max(x1) && y >= y0.min(y1) && y <= y0.max(y1)
            }
            Shape::Circle([cx, cy, r]) => (x - cx).powi(2) + (y - cy).powi(2) <= r * r,
        }
    }
}

/// The information map: zones of interest with scores 0–100 (paper 000 §II: I_xy),
/// painted in order over a default score, or a grey image (0 → 0, 255 → 100) of the
/// same size as the map.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InformationSpec {
    #[serde(default)]
    pub default_score: u8,
    #[serde(default)]
    pub image: Option<PathBuf>,
    #[serde(default)]
    pub zones: Vec<Zone>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Zone {
    pub name: String,
    pub score: u8,
    /// `[x0, y0, x1, y1]`: give this or `circle`.
    #[serde(default)]
    pub rect: Option<[f64; 4]>,
    /// `[cx, cy, radius]`: give this or `rect`.
    #[serde(default)]
    pub circle: Option<[f64; 3]>,
}

impl Zone {
    /// The zone's shape, or `None` unless exactly one of `rect` and `circle` is given.
    pub fn shape(&self) -> Option<Shape> {
        match (self.rect, self.circle) {
            (Some(r), None) => Some(Shape::Rect(r)),
            (None, Some(c)) => Some(Shape::Circle(c)),
            _ => None,
        }
    }
}

/// A named point in the world (a start, a goal, a task's place), metres.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Place {
    pub name: String,
    pub at: [f64; 2],
}

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
}

/// Reads a scenario file and builds its grids.
pub fn load(path: &Path, max_cells: u64) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
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
    parse(path, &text, max_cells)
}

/// Parses scenario text; `path` names the file in errors and anchors relative paths.
pub fn parse(path: &Path, text: &str, max_cells: u64) -> Result<Scenario, ScenarioError> {
    let file: ScenarioFile = serde_yaml_ng::from_str(text).map_err(|e| ScenarioError::Invalid {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    let field = |field: &str, reason: String| ScenarioError::Field {
        path: path.to_owned(),
        field: field.to_owned(),
        reason,
    };
    let base = path.parent().unwrap_or_else(|| Path::new("."));
    let occupancy = match &file.map {
        MapSource::Ros(map_yaml) => {
            ros_map::load(&base.join(map_yaml), max_cells)
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
        Some(spec) => build_information(spec, &occupancy.meta, base, max_cells)
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
    Ok(Scenario {
        file,
        occupancy,
        information,
    })
}

fn build_grid(spec: &GridSpec, max_cells: u64) -> Result<Grid<i8>, String> {
    let [wm, hm] = spec.size_m;
    if !(spec.resolution.is_finite() && spec.resolution > 0.0) {
        return Err(format!(
            "resolution must be a positive number of metres per cell, got {}",
            spec.resolution
        ));
    }
    if !(wm.is_finite() && hm.is_finite() && wm > 0.0 && hm > 0.0) {
        return Err(format!(
            "size_m must be two positive numbers, got [{wm}, {hm}]"
        ));
    }
    let (w, h) = (
        (wm / spec.resolution).round(),
        (hm / spec.resolution).round(),
    );
    if w * h > max_cells as f64 {
        return Err(format!(
            "the grid has {} cells; the limit max_layer_cells is {max_cells}",
            w * h
        ));
    }
    let meta = GridMeta {
        width: w as u32,
        height: h as u32,
        resolution: spec.resolution,
        origin: Origin {
            x: spec.origin[0],
            y: spec.origin[1],
            yaw: 0.0,
        },
    };
    let mut grid = Grid::filled(meta, occupancy::FREE);
    let (w, h) = (grid.width(), grid.height());
    for y in 0..h {
        for x in 0..w {
            let border = spec.border_walls && (x == 0 || y == 0 || x == w - 1 || y == h - 1);
            let (cx, cy) = cell_center(&meta, x, y);
            if border || spec.obstacles.iter().any(|s| s.contains(cx, cy)) {
                grid.cells[y * w + x] = occupancy::OCCUPIED;
            }
        }
    }
    Ok(grid)
}

fn build_information(
    spec: &InformationSpec,
    meta: &GridMeta,
    base: &Path,
    max_cells: u64,
) -> Result<Grid<u8>, (String, String)> {
    if spec.default_score > 100 {
        return Err((
            "information.default_score".into(),
            format!("scores are 0..=100, got {}", spec.default_score),
        ));
    }
    let mut grid = Grid::filled(*meta, spec.default_score);
    if let Some(image) = &spec.image {
        let image_path = base.join(image);
        let fail = |reason: String| {
            (
                "information.image".to_owned(),
                format!("{}: {reason}", image_path.display()),
            )
        };
        let decoded = image::open(&image_path)
            .map_err(|e| fail(e.to_string()))?
            .to_luma8();
        if (decoded.width(), decoded.height()) != (meta.width, meta.height) {
            return Err(fail(format!(
                "the image is {}x{} but the map is {}x{}",
                decoded.width(),
                decoded.height(),
                meta.width,
                meta.height
            )));
        }
        if u64::from(decoded.width()) * u64::from(decoded.height()) > max_cells {
            return Err(fail(format!(
                "more than max_layer_cells = {max_cells} cells"
            )));
        }
        let h = meta.height as usize;
        for (x, y, p) in decoded.enumerate_pixels() {
            let row = h - 1 - y as usize;
            grid.cells[row * meta.width as usize + x as usize] =
                ((f64::from(p.0[0]) * 100.0 / 255.0).round()) as u8;
        }
    }
    for (i, zone) in spec.zones.iter().enumerate() {
        if zone.score > 100 {
            return Err((
                format!("information.zones[{i}].score"),
                format!(
                    "zone '{}': scores are 0..=100, got {}",
                    zone.name, zone.score
                ),
            ));
        }
        let shape = zone.shape().ok_or_else(|| {
            (
                format!("information.zones[{i}]"),
                format!("zone '{}' needs exactly one of rect or circle", zone.name),
            )
        })?;
        let (w, h) = (grid.width(), grid.height());
        for y in 0..h {
            for x in 0..w {
                let (cx, cy) = cell_center(meta, x, y);
                if shape.contains(cx, cy) {
                    grid.cells[y * w + x] = zone.score;
                }
            }
        }
    }
    Ok(grid)
}
