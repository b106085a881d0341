//! The memory budget across all layers (`max_total_cell_bytes`): what the layers hold,
//! and what they would hold after a whole-layer change, worked out from the sizes the
//! change names, before anything is staged, inflated or persisted.
//!
//! A `set_cells` change keeps every size, so only a replace or a map load can grow the
//! total; each names its grid, which fixes the size of every layer it makes (the source,
//! its derived layer, a resized information map).

use roam_proto::cells::Dtype;
use roam_proto::map::GridMeta;

use super::error::limit;
use super::{LayerStore, StoreError, HEURISTIC, INFLATED, INFORMATION, OCCUPANCY};
use roam_world::layers::block_size;

/// Bytes of cells of a layer of `meta` and `dtype`.
pub(super) fn cell_bytes(meta: &GridMeta, dtype: Dtype) -> u64 {
    meta.cell_count() * dtype.size() as u64
}

impl LayerStore {
    /// Bytes of cells the layers hold now.
    pub fn held_cell_bytes(&self) -> u64 {
        self.layers
            .values()
            .map(|l| l.cells.len() as u64 * l.cells.dtype().size() as u64)
            .sum()
    }

    /// Bytes of cells layer `name` holds now (0 when it does not exist).
    fn bytes_of(&self, name: &str) -> u64 {
        self.layers
            .get(name)
            .map_or(0, |l| cell_bytes(&l.meta, l.cells.dtype()))
    }

    /// The sizes a whole new layer `name` of `meta` and `dtype` makes: itself, and for a
    /// source what follows from it (`inflated`; an information map resized to a new
    /// occupancy size, unless `information_given`; `heuristic`).
    pub(super) fn sizes_after<'n>(
        &self,
        name: &'n str,
        meta: &GridMeta,
        dtype: Dtype,
        information_given: bool,
    ) -> Vec<(&'n str, u64)> {
        let heuristic = |meta: &GridMeta| {
            let block = block_size(
                meta.width as usize,
                meta.height as usize,
                self.derived.heuristic_compression,
            ) as u64;
            let blocks = u64::from(meta.width).div_ceil(block.max(1))
                * u64::from(meta.height).div_ceil(block.max(1));
            (HEURISTIC, blocks * Dtype::F32.size() as u64)
        };
        match name {
            OCCUPANCY => {
                let mut sizes = vec![
                    (OCCUPANCY, cell_bytes(meta, Dtype::I8)),
                    (INFLATED, cell_bytes(meta, Dtype::I8)),
                ];
                let info_meta = self.layers.get(INFORMATION).map(|l| l.meta);
                if information_given || info_meta != Some(*meta) {
                    sizes.push((INFORMATION, cell_bytes(meta, Dtype::U8)));
                    sizes.push(heuristic(meta));
                }
                sizes
            }
            INFORMATION => vec![(INFORMATION, cell_bytes(meta, Dtype::U8)), heuristic(meta)],
            _ => vec![(name, cell_bytes(meta, dtype))],
        }
    }

    /// Refuses a change of layer `name` making layers of `sizes` (from
    /// [`LayerStore::sizes_after`]) when the layers would then hold more than
    /// `max_total_cell_bytes`.
    pub(super) fn check_budget(&self, name: &str, sizes: &[(&str, u64)]) -> Result<(), StoreError> {
        let max = self.limits.max_total_cell_bytes;
        let held = self.held_cell_bytes();
        let (freed, added) = sizes.iter().fold((0u64, 0u64), |(freed, added), (n, b)| {
            (freed + self.bytes_of(n), added + b)
        });
        let after = held.saturating_sub(freed).saturating_add(added);
        if after > max {
            return Err(limit(
                "max_total_cell_bytes",
                max,
                after,
                format!(
                    "bytes of cells held across all layers after this change of '{name}' (the layers hold {held} now; delete a layer with <root>/map/delete/<name>, or send a smaller one)"
                ),
            ));
        }
        Ok(())
    }
}
