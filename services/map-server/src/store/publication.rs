//! What followers are told of a committed change: the whole layer, or, for cell edits,
//! only the cells written ([`LayerDelta`]), so a one-cell update of a 4096 × 4096 layer
//! goes out as a message of a few hundred bytes instead of the 90 MB layer.

use roam_proto::cells::Cells;
use roam_proto::layer_delta::{CellPositions, LayerDelta, MAX_DELTA_CELLS};
use roam_proto::map::Layer;

use crate::edits::CellEdits;

/// A delta is published only while it is at most this share of the layer's cell bytes
/// (8 bytes of position and the value per cell, against the value per cell); a larger
/// change goes out as the whole layer, which is then smaller and as quick to apply.
pub const DELTA_MAX_SHARE: u64 = 4;

/// How one layer of a committed change is published.
#[derive(Debug, Clone, PartialEq)]
pub enum Publication {
    /// The whole layer, as the store holds it when it is published.
    Whole(String),
    /// The cells a `set_cells` change (or its derived layer) wrote.
    Delta(LayerDelta),
}

impl Publication {
    /// The layer published.
    pub fn name(&self) -> &str {
        match self {
            Publication::Whole(name) => name,
            Publication::Delta(delta) => &delta.name,
        }
    }
}

/// The publication of `edits` to `layer` (as it is before them), which make `version`:
/// a delta when it is small enough, else the whole layer.
pub(super) fn of_edits(layer: &Layer, version: u64, edits: &CellEdits) -> Publication {
    let dtype = layer.cells.dtype().size() as u64;
    let delta_bytes = edits.len() as u64 * (8 + dtype);
    let layer_bytes = layer.cells.len() as u64 * dtype;
    if edits.len() > MAX_DELTA_CELLS || delta_bytes * DELTA_MAX_SHARE > layer_bytes {
        return Publication::Whole(layer.name.clone());
    }
    Publication::Delta(LayerDelta {
        name: layer.name.clone(),
        base_version: layer.version,
        version,
        positions: CellPositions(edits.positions.clone()),
        values: Cells::clone(&edits.values),
    })
}
