//! Messages of the map server: layers, their versions, updates and loads.

use serde::{Deserialize, Serialize};

use crate::cells::{Cells, Dtype};
use crate::codec::Message;

/// Where a grid sits in the world: size in cells, metres per cell, and the world pose
/// of the corner of cell (0, 0) (ROS `origin`: x, y in metres, yaw in radians).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridMeta {
    pub width: u32,
    pub height: u32,
    /// Metres per cell.
    pub resolution: f64,
    pub origin: Origin,
}

/// A planar pose: metres and radians.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Origin {
    pub x: f64,
    pub y: f64,
    #[serde(default)]
    pub yaw: f64,
}

impl GridMeta {
    /// Number of cells (`width * height`), without overflow.
    pub fn cell_count(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }
}

/// The map server's base layers, by name (`<root>/map/layer/<name>`): the occupancy
/// grid (i8, -1 unknown, 0..=100), its inflation by the robot radius (i8), the
/// information map (u8, paper 000's 0..=100 scores) and paper 000's heuristic map (u8).
pub const OCCUPANCY_LAYER: &str = "occupancy";
pub const INFLATED_LAYER: &str = "inflated";
pub const INFORMATION_LAYER: &str = "information";
pub const HEURISTIC_LAYER: &str = "heuristic";

/// One layer as the map server holds it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    pub name: String,
    /// Starts at 1 and grows by one with each accepted change.
    pub version: u64,
    pub meta: GridMeta,
    /// The layer this one is computed from (`inflated` from `occupancy`, `heuristic`
    /// from `information`); derived layers cannot be written directly.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub derived_from: Option<String>,
    pub cells: Cells,
}

impl Message for Layer {
    const KIND: &'static str = "layer";
}

/// A layer without its cells.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerInfo {
    pub name: String,
    pub version: u64,
    pub meta: GridMeta,
    pub dtype: Dtype,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub derived_from: Option<String>,
}

/// Every layer the map server holds, and what it had to tell about its state (a
/// persisted file found corrupt and the copy it fell back to, for example).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerList {
    pub layers: Vec<LayerInfo>,
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The world the map server holds: the map it loaded (absent from an old server, or
    /// one restored from a data dir that never recorded it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world: Option<WorldId>,
}

/// Which world (map) a service works on: `hash` identifies it (a hash of the occupancy
/// grid's placement and cells as loaded), `name` is for people (the scenario's name or
/// the map file's stem). Two services are on the same world when their hashes agree.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldId {
    pub name: String,
    pub hash: String,
}

impl std::fmt::Display for WorldId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "'{}' ({})", self.name, self.hash)
    }
}

impl Message for LayerList {
    const KIND: &'static str = "layer_list";
}

/// A change to one layer, based on the version the writer last saw. The map server
/// refuses it with `stale_version` when the layer has moved on, so two writers never
/// silently overwrite each other. `base_version` 0 means "the layer does not exist yet".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerUpdate {
    pub base_version: u64,
    pub change: LayerChange,
    /// The world the writer computed the change on; the map server refuses a change made
    /// for another world than its own (a PEB layer of another map, say). Absent: not
    /// checked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world: Option<WorldId>,
}

impl Message for LayerUpdate {
    const KIND: &'static str = "layer_update";
}

/// The most cell writes one `set_cells` can carry, whatever the map server's configured
/// `max_cells_per_update` (which may only be lower).
pub const MAX_WIRE_CELL_WRITES: usize = 1_048_576;

/// What a [`LayerUpdate`] does.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum LayerChange {
    /// Set individual cells (grid indices, row 0 at the origin); at most
    /// [`MAX_WIRE_CELL_WRITES`] on the wire (the parse stops at one more), and at most
    /// the map server's `max_cells_per_update`.
    SetCells {
        #[serde(deserialize_with = "crate::bounded::vec::<_, MAX_WIRE_CELL_WRITES, _>")]
        cells: Vec<CellWrite>,
    },
    /// Replace the whole layer, possibly with another size or element type.
    Replace { meta: GridMeta, cells: Cells },
}

/// One cell write: column `x`, row `y`, and the new value (rounded to the layer's type).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellWrite {
    pub x: u32,
    pub y: u32,
    pub value: f64,
}

/// The answer to an accepted [`LayerUpdate`]: the layer's new version, and the derived
/// layers that were recomputed with it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UpdateAck {
    pub layer: String,
    pub version: u64,
    #[serde(default)]
    pub derived: Vec<LayerInfo>,
}

impl Message for UpdateAck {
    const KIND: &'static str = "update_ack";
}

/// Ask the map server to load a map file from its own file system: a ROS `map.yaml`
/// (occupancy) or a roam scenario (occupancy and information). When `base_version` is
/// given, the load is refused if `occupancy` has moved past it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadMap {
    pub path: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_version: Option<u64>,
}

impl Message for LoadMap {
    const KIND: &'static str = "load_map";
}

/// Ask the map server to delete a layer, based on the version the writer last saw
/// (refused with `stale_version` when the layer has moved on, like an update). Only
/// free layers can be deleted: `occupancy`, `information` and their derived `inflated`
/// and `heuristic` are refused with `invalid_request`, a layer that does not exist
/// with `not_found`.
///
/// What followers see: nothing is published on `<root>/map/layer/<name>` (no
/// tombstone); from the reply on, a `get` of the layer answers `not_found` and
/// `<root>/map/layers` no longer lists it. A layer created again under the same name
/// (a replace based on version 0) goes on from the deleted one's version (it gets
/// `version + 1`), so a follower that keeps the newest version takes it, and a writer
/// still holding a version of the deleted layer is refused as stale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeleteLayer {
    pub base_version: u64,
}

impl Message for DeleteLayer {
    const KIND: &'static str = "delete_layer";
}

/// The answer to an accepted [`DeleteLayer`]: the layer and the version it had.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerDeleted {
    pub layer: String,
    pub version: u64,
}

impl Message for LayerDeleted {
    const KIND: &'static str = "layer_deleted";
}
