//! Staging a change: the new version of every layer it touches, derived layers
//! included, before anything is persisted or installed.
//!
//! A whole-layer change (a replace, a map load) stages whole layers. A `set_cells`
//! change stages cell edits, and the derived layer follows with the edits it gains,
//! found over a window around them ([`crate::derived`]); so a one-cell change costs a
//! few cells of work, memory and disk, never a copy of the layer. A change stages
//! whole layers anyway when the data dir would rather write a snapshot of it.

use roam_proto::cells::Cells;
use roam_proto::map::{GridMeta, Layer};

use super::pending::{Change, Pending, Staged};
use super::{LayerStore, StoreError, HEURISTIC, INFLATED, INFORMATION, OCCUPANCY};
use crate::derived::{self, Derivation};
use crate::edits::CellEdits;
use crate::persist::log::record_bytes;
use roam_world::grid::{occupancy, Grid};
use roam_world::layers;

impl LayerStore {
    /// Stages a whole layer at its next version.
    fn stage_full(
        &self,
        pending: &mut Pending,
        name: &str,
        meta: GridMeta,
        derivation: Option<Derivation>,
        cells: Cells,
    ) {
        let version = self.next_version(name);
        pending.put(Staged {
            name: name.to_owned(),
            version,
            derivation,
            change: Change::Full(Layer {
                name: name.to_owned(),
                version,
                meta,
                derived_from: super::derived_source(name).map(str::to_owned),
                cells,
            }),
        });
    }

    /// Stages `edits` to layer `current` at `version`: as edits, or as the whole edited
    /// layer when the data dir would rather write a snapshot than log them.
    fn stage_edits_of(
        &self,
        pending: &mut Pending,
        current: &Layer,
        version: u64,
        derivation: Option<Derivation>,
        edits: CellEdits,
    ) {
        let bytes = record_bytes(edits.len(), current.cells.dtype());
        let change = if self
            .data
            .as_ref()
            .is_some_and(|d| d.prefers_snapshot(&current.name, bytes))
        {
            let mut layer = current.clone();
            edits.apply(&layer.meta, &mut layer.cells);
            layer.version = version;
            Change::Full(layer)
        } else {
            Change::Edits(edits)
        };
        pending.put(Staged {
            name: current.name.clone(),
            version,
            derivation,
            change,
        });
    }

    /// Stages checked cell edits of layer `name` and what follows from them.
    pub(super) fn stage_cell_edits(
        &self,
        pending: &mut Pending,
        name: &str,
        edits: CellEdits,
    ) -> Result<(), StoreError> {
        let Some(current) = self.layers.get(name) else {
            return Err(StoreError::NotFound(name.to_owned()));
        };
        let version = self.next_version(name);
        let mut derived = Pending::default();
        match name {
            OCCUPANCY => self.stage_inflated_after(&mut derived, current, version, &edits),
            INFORMATION => self.stage_heuristic_after(&mut derived, current, version, &edits),
            _ => {}
        }
        // The source first: it is persisted before what is derived from it.
        self.stage_edits_of(pending, current, version, None, edits);
        pending.staged.extend(derived.staged);
        Ok(())
    }

    /// `inflated` after `edits` to occupancy `current` (which becomes `version`): the
    /// cells a window around the edits changes when `inflated` is in step, else all of
    /// it computed again.
    fn stage_inflated_after(
        &self,
        pending: &mut Pending,
        current: &Layer,
        version: u64,
        edits: &CellEdits,
    ) {
        let recipe = self.derived.inflate();
        let derivation = Derivation {
            source_version: version,
            recipe,
        };
        let inflated = self.layers.get(INFLATED);
        let in_step = self.derivations.get(INFLATED)
            == Some(&Derivation {
                source_version: current.version,
                recipe,
            });
        if let (true, Some(inflated), Cells::I8(occ), Some(Cells::I8(infl))) = (
            in_step,
            inflated,
            &current.cells,
            inflated.map(|l| &l.cells),
        ) {
            if let Some(changes) = derived::inflated_changes(
                &current.meta,
                occ,
                infl,
                edits,
                self.derived.robot_radius_m,
                self.derived.lethal_threshold,
            ) {
                let next = self.next_version(INFLATED);
                self.stage_edits_of(pending, inflated, next, Some(derivation), changes);
                return;
            }
        }
        let mut cells = current.cells.clone();
        edits.apply(&current.meta, &mut cells);
        if let Cells::I8(values) = cells {
            self.stage_inflated(pending, current.meta, values, version);
        }
    }

    /// `heuristic` after `edits` to information `current` (which becomes `version`).
    fn stage_heuristic_after(
        &self,
        pending: &mut Pending,
        current: &Layer,
        version: u64,
        edits: &CellEdits,
    ) {
        let recipe = self.derived.heuristic();
        let derivation = Derivation {
            source_version: version,
            recipe,
        };
        let heuristic = self.layers.get(HEURISTIC);
        let in_step = self.derivations.get(HEURISTIC)
            == Some(&Derivation {
                source_version: current.version,
                recipe,
            });
        if let (true, Some(heuristic), Cells::U8(info), Some(Cells::F32(h))) = (
            in_step,
            heuristic,
            &current.cells,
            heuristic.map(|l| &l.cells),
        ) {
            if let Some(changes) = derived::heuristic_changes(
                &current.meta,
                info,
                h,
                edits,
                self.derived.heuristic_compression,
            ) {
                let next = self.next_version(HEURISTIC);
                self.stage_edits_of(pending, heuristic, next, Some(derivation), changes);
                return;
            }
        }
        let mut cells = current.cells.clone();
        edits.apply(&current.meta, &mut cells);
        if let Cells::U8(values) = cells {
            self.stage_heuristic(pending, current.meta, values, version);
        }
    }

    /// Stages `inflated` computed from occupancy cells `values` of `meta`, which are
    /// occupancy's `source_version`.
    pub(super) fn stage_inflated(
        &self,
        pending: &mut Pending,
        meta: GridMeta,
        values: Vec<i8>,
        source_version: u64,
    ) {
        let grid = Grid {
            meta,
            cells: values,
        };
        let inflated = layers::inflate(
            &grid,
            self.derived.robot_radius_m,
            self.derived.lethal_threshold,
        );
        let derivation = Derivation {
            source_version,
            recipe: self.derived.inflate(),
        };
        self.stage_full(
            pending,
            INFLATED,
            meta,
            Some(derivation),
            Cells::I8(inflated.cells),
        );
    }

    /// Stages `heuristic` computed from information scores `values` of `meta`, which
    /// are information's `source_version`.
    pub(super) fn stage_heuristic(
        &self,
        pending: &mut Pending,
        meta: GridMeta,
        values: Vec<u8>,
        source_version: u64,
    ) {
        let grid = Grid {
            meta,
            cells: values,
        };
        let heuristic = layers::heuristic(&grid, self.derived.heuristic_compression);
        let derivation = Derivation {
            source_version,
            recipe: self.derived.heuristic(),
        };
        self.stage_full(
            pending,
            HEURISTIC,
            heuristic.meta,
            Some(derivation),
            Cells::F32(heuristic.cells),
        );
    }

    /// Stages a new whole source layer and what follows from it: `inflated` for
    /// occupancy, and an information map resized to a new occupancy size.
    pub(super) fn stage_source(
        &self,
        pending: &mut Pending,
        name: &str,
        meta: GridMeta,
        cells: Cells,
        information: Option<Cells>,
    ) -> Result<(), StoreError> {
        if name == OCCUPANCY {
            let Cells::I8(values) = &cells else {
                return Err(StoreError::Invalid(
                    "occupancy cells must be i8 (ROS values -1, 0..=100)".into(),
                ));
            };
            if let Some(bad) = values
                .iter()
                .find(|&&v| !(occupancy::UNKNOWN..=occupancy::OCCUPIED).contains(&v))
            {
                return Err(StoreError::Invalid(format!(
                    "occupancy values are -1 (unknown) or 0..=100, got {bad}"
                )));
            }
            let version = self.next_version(OCCUPANCY);
            let values = values.clone();
            self.stage_full(pending, name, meta, None, cells);
            self.stage_inflated(pending, meta, values, version);
            let info_meta = self.layers.get(INFORMATION).map(|l| l.meta);
            match information {
                Some(info) => self.stage_information(pending, meta, info)?,
                None if info_meta != Some(meta) => {
                    // The information map must cover the same cells as occupancy.
                    self.stage_information_unchecked(
                        pending,
                        meta,
                        vec![0; meta.cell_count() as usize],
                    );
                }
                None => {}
            }
            return Ok(());
        }
        if let Cells::F32(v) = &cells {
            // Infinity is a value (an unbounded PEB, say); NaN is never one.
            if let Some(bad) = v.iter().find(|c| c.is_nan()) {
                return Err(StoreError::Invalid(format!(
                    "layer '{name}' cells must be numbers (infinity is allowed), got {bad}"
                )));
            }
        }
        self.stage_full(pending, name, meta, None, cells);
        Ok(())
    }

    /// Stages a whole information map (checked: scores, and occupancy's size) and its
    /// heuristic.
    pub(super) fn stage_information(
        &self,
        pending: &mut Pending,
        meta: GridMeta,
        cells: Cells,
    ) -> Result<(), StoreError> {
        let Cells::U8(values) = cells else {
            return Err(StoreError::Invalid(
                "information cells must be u8 scores 0..=100".into(),
            ));
        };
        if let Some(bad) = values.iter().find(|&&v| v > 100) {
            return Err(StoreError::Invalid(format!(
                "information scores are 0..=100, got {bad}"
            )));
        }
        let occupancy_meta = pending
            .meta_of(OCCUPANCY)
            .or_else(|| self.layers.get(OCCUPANCY).map(|l| l.meta));
        if let Some(occ) = occupancy_meta {
            if occ != meta {
                return Err(StoreError::Invalid(format!(
                    "the information map must have the occupancy grid's size and placement ({}x{} at {} m/cell), got {}x{} at {} m/cell",
                    occ.width, occ.height, occ.resolution, meta.width, meta.height, meta.resolution
                )));
            }
        }
        self.stage_information_unchecked(pending, meta, values);
        Ok(())
    }

    pub(super) fn stage_information_unchecked(
        &self,
        pending: &mut Pending,
        meta: GridMeta,
        values: Vec<u8>,
    ) {
        let version = self.next_version(INFORMATION);
        self.stage_full(pending, INFORMATION, meta, None, Cells::U8(values.clone()));
        self.stage_heuristic(pending, meta, values, version);
    }
}
