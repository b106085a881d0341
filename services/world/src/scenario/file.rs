//! The scenario file as written: its top-level struct and the map server's sections
//! (the map, its shapes, the information zones, named places). The sim world's sections
//! are typed in `sim_sections` and `motion`.

use std::path::PathBuf;

use serde::Deserialize;

use super::changes::ChangeZoneSpec;
use super::motion::{MotionSpec, RobotStart};
use super::sim_sections::{BlockSpec, SensingSpec, TimeSpec, WalkerSpec};

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
    /// Sim world: the anchors (paper 002 §2), fixed beacons at known positions that a
    /// robot measures its TOA range to. World metres; an anchor may stand on a wall.
    #[serde(default)]
    pub anchors: Vec<Place>,
    /// Sim world: the range sensor and the local grid observation.
    #[serde(default)]
    pub sensing: SensingSpec,
    /// Sim world: the robots' motion model (paper 002 Eq. 1's point, or roam's
    /// unicycle). Its `model` enum is written as a plain name or a one-key map too.
    #[serde(default, with = "serde_yaml_ng::with::singleton_map_recursive")]
    pub motion: MotionSpec,
    /// Sim world: the robots, where each starts (world metres, on a free cell) and its
    /// heading there (radians, default 0; only a unicycle has one).
    #[serde(default)]
    pub robots: Vec<RobotStart>,
    /// Sim world: scripted moving obstacles (paper 004 §5's two blocks).
    #[serde(default)]
    pub blocks: Vec<BlockSpec>,
    /// Sim world: obstacles that wander at random.
    #[serde(default)]
    pub walkers: Vec<WalkerSpec>,
    /// Sim world: semi-static objects that appear in zones and vanish again
    /// ([`super::changes`]).
    #[serde(default)]
    pub changes: Vec<ChangeZoneSpec>,
    /// A mission's waypoints in the order they are visited (paper 002 ES2: A, B, C, D).
    #[serde(default)]
    pub waypoints: Vec<Place>,
    /// Sim world: the clock.
    #[serde(default)]
    pub time: TimeSpec,
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
