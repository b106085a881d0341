//! The store's limits and the parameters of its derived layers.

use crate::derived::Recipe;

/// Size limits. Each is named in the error that enforces it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Limits {
    /// Cells in one layer (default 16,777,216 = 4096²; a 1 km² site at 0.25 m). Also
    /// bounds the layer files read back: 4 bytes a cell and a 64 KiB header.
    pub max_layer_cells: u64,
    /// Cells written by one `set_cells` update.
    pub max_cells_per_update: u64,
    /// Bytes of one request payload.
    pub max_request_bytes: u64,
    /// Layers held at once.
    pub max_layers: u64,
    /// Bytes of cells held across all layers together (1 byte a cell for i8 and u8, 4 for
    /// f32). `max_layers` full-size layers from anonymous writers would otherwise reach
    /// about 4 GiB of cells (f32) and as much again encoded: a change that would hold
    /// more is refused before it is staged.
    pub max_total_cell_bytes: u64,
}

pub const DEFAULT_LIMITS: Limits = Limits {
    max_layer_cells: roam_world::DEFAULT_MAX_CELLS,
    max_cells_per_update: 100_000,
    max_request_bytes: 96 * 1024 * 1024,
    max_layers: 64,
    max_total_cell_bytes: DEFAULT_MAX_TOTAL_CELL_BYTES,
};

/// The default of [`Limits::max_total_cell_bytes`]: 1 GiB. A 1.7-million-cell
/// warehouse map with its derived layers, localization's PEB and the mapper's four
/// layers holds about 34 MB (i8 and u8 layers 1.7 MB each, f32 layers 6.8 MB), so 30
/// such sets fit; so do 16 full-size (4096²) f32 layers.
pub const DEFAULT_MAX_TOTAL_CELL_BYTES: u64 = 1 << 30;

impl Default for Limits {
    fn default() -> Self {
        DEFAULT_LIMITS
    }
}

/// How the derived layers are made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DerivedParams {
    /// Robot radius for `inflated`, metres.
    pub robot_radius_m: f64,
    /// Heuristic compression c_h for `heuristic` (paper 000 Table I: 0.25).
    pub heuristic_compression: f64,
    /// Occupancy value from which a cell is an obstacle (Nav2: occupied_thresh · 100).
    pub lethal_threshold: i8,
}

impl Default for DerivedParams {
    fn default() -> Self {
        DerivedParams {
            robot_radius_m: 0.2,
            heuristic_compression: 0.25,
            lethal_threshold: 65,
        }
    }
}

impl DerivedParams {
    /// The recipe of `inflated`.
    pub fn inflate(&self) -> Recipe {
        Recipe::Inflate {
            robot_radius_m: self.robot_radius_m,
            lethal_threshold: self.lethal_threshold,
        }
    }

    /// The recipe of `heuristic`.
    pub fn heuristic(&self) -> Recipe {
        Recipe::Heuristic {
            compression: self.heuristic_compression,
        }
    }
}
