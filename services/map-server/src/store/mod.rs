//! The layer store: every layer with its version, the rules for changing them, and
//! the derived layers kept in step. Plain Rust, no network: the Zenoh adapter in
//! [`crate::service`] turns messages into calls on it.
//!
//! Layers:
//! - `occupancy` (i8, ROS values) and `information` (u8, scores 0–100) are sources;
//! - `inflated` (from occupancy, robot radius) and `heuristic` (from information,
//!   compression c_h) are derived and recomputed whenever their source changes; each
//!   carries the [`Derivation`] it was computed with, so it is never served out of step
//!   with its source, also after a crash or a restore ([`restore`]);
//! - any other name (`change_rate`, `peb`, ...) is a free layer that its writer owns,
//!   and may delete.
//!
//! Every change names the version it was based on; a stale one is refused. Changes are
//! persisted before they become visible, so a reply never acknowledges what a restart
//! would lose. The layers of one change are installed together: a reader sees either
//! all of them or none.

mod budget;
mod commit;
mod error;
mod limits;
mod pending;
mod publication;
pub mod restore;
mod stage;

use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

use roam_proto::cells::Dtype;
use roam_proto::keys;
use roam_proto::map::{
    GridMeta, Layer, LayerChange, LayerDeleted, LayerInfo, LayerList, LayerUpdate, UpdateAck,
    WorldId,
};

pub use error::StoreError;
pub use limits::{DerivedParams, Limits, DEFAULT_LIMITS, DEFAULT_MAX_TOTAL_CELL_BYTES};
pub use publication::{Publication, DELTA_MAX_SHARE};

pub use crate::derived::derived_source;
use crate::derived::Derivation;
use crate::edits::CellEdits;
use crate::persist::{DataDir, Tombstone, MAX_TOMBSTONES};
use error::limit;
use pending::Pending;
use roam_world::grid::Grid;

pub use roam_proto::map::{
    HEURISTIC_LAYER as HEURISTIC, INFLATED_LAYER as INFLATED, INFORMATION_LAYER as INFORMATION,
    OCCUPANCY_LAYER as OCCUPANCY,
};

/// The layers every stack needs, which cannot be deleted.
pub const BASE_LAYERS: [&str; 4] = [OCCUPANCY, INFORMATION, INFLATED, HEURISTIC];

/// Warnings kept for `map/layers` (the oldest are dropped first); each is also logged.
pub const MAX_WARNINGS: usize = 64;

/// The map server's layers.
#[derive(Debug)]
pub struct LayerStore {
    /// Shared with readers: a reader holding one keeps a consistent copy while a
    /// change installs the next (which then copies the cells once).
    layers: BTreeMap<String, Arc<Layer>>,
    /// What each derived layer was computed from.
    derivations: BTreeMap<String, Derivation>,
    /// Deleted (or lost) layers' last versions, oldest first: a layer created again
    /// goes on from there.
    tombstones: Vec<Tombstone>,
    limits: Limits,
    derived: DerivedParams,
    data: Option<DataDir>,
    warnings: VecDeque<String>,
    /// The world (map) the layers are of, as last loaded.
    world: Option<WorldId>,
}

impl LayerStore {
    pub fn new(limits: Limits, derived: DerivedParams, data: Option<DataDir>) -> Self {
        LayerStore {
            layers: BTreeMap::new(),
            derivations: BTreeMap::new(),
            tombstones: Vec::new(),
            limits,
            derived,
            data,
            warnings: VecDeque::new(),
            world: None,
        }
    }

    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// Changes the robot radius used for `inflated` from the next occupancy change on.
    pub fn set_robot_radius(&mut self, radius_m: f64) {
        self.derived.robot_radius_m = radius_m;
    }

    /// The parameters the derived layers are computed with.
    pub fn derived_params(&self) -> &DerivedParams {
        &self.derived
    }

    pub fn get(&self, name: &str) -> Option<&Layer> {
        self.layers.get(name).map(Arc::as_ref)
    }

    /// A layer to read outside the store's lock: it stays as it is while the store
    /// moves on.
    pub fn get_shared(&self, name: &str) -> Option<Arc<Layer>> {
        self.layers.get(name).cloned()
    }

    /// What a derived layer was computed from.
    pub fn derivation(&self, name: &str) -> Option<&Derivation> {
        self.derivations.get(name)
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.layers.keys().map(String::as_str)
    }

    pub fn version(&self, name: &str) -> u64 {
        self.layers.get(name).map_or(0, |l| l.version)
    }

    /// The version the next change of `name` makes: one above the layer's, or above the
    /// last version of a deleted layer of that name.
    fn next_version(&self, name: &str) -> u64 {
        let floor = self
            .tombstones
            .iter()
            .find(|t| t.name == name)
            .map_or(0, |t| t.version);
        self.version(name).max(floor) + 1
    }

    /// Every layer's info, the warnings found while restoring and running, and the
    /// world.
    pub fn list(&self) -> LayerList {
        LayerList {
            layers: self.layers.values().map(|l| info(l)).collect(),
            warnings: self.warnings.iter().cloned().collect(),
            world: self.world.clone(),
        }
    }

    /// The world (map) the layers are of.
    pub fn world(&self) -> Option<&WorldId> {
        self.world.as_ref()
    }

    /// Records which world the layers are of (after loading its map), in the data dir
    /// too.
    pub fn set_world(&mut self, world: WorldId) -> Result<(), StoreError> {
        if let Some(data) = &self.data {
            data.save_world(&world)?;
        }
        self.world = Some(world);
        Ok(())
    }

    /// Logs a warning and keeps it for `map/layers`.
    fn warn(&mut self, warning: String) {
        tracing::error!("{warning}");
        if self.warnings.len() >= MAX_WARNINGS {
            self.warnings.pop_front();
        }
        self.warnings.push_back(warning);
    }

    /// Replaces occupancy (and information, when given) from a loaded map. Refused when
    /// `base_version` is given and occupancy has moved past it. Returns the changed names.
    pub fn load_map(
        &mut self,
        occupancy_grid: Grid<i8>,
        information: Option<Grid<u8>>,
        base_version: Option<u64>,
    ) -> Result<Vec<String>, StoreError> {
        if let Some(base) = base_version {
            self.check_base(OCCUPANCY, base, "load", "load the map again")?;
        }
        self.check_size(&occupancy_grid.meta)?;
        let sizes = self.sizes_after(
            OCCUPANCY,
            &occupancy_grid.meta,
            Dtype::I8,
            information.is_some(),
        );
        self.check_budget(OCCUPANCY, &sizes)?;
        let mut pending = Pending::default();
        let info_cells = information.map(|g| roam_proto::cells::Cells::U8(g.cells));
        let before = self.occupancy_meta();
        self.stage_source(
            &mut pending,
            OCCUPANCY,
            occupancy_grid.meta,
            roam_proto::cells::Cells::I8(occupancy_grid.cells),
            info_cells,
        )?;
        let changed = names(&self.commit(pending)?);
        self.follow_occupancy_grid(before)?;
        Ok(changed)
    }

    fn occupancy_meta(&self) -> Option<GridMeta> {
        self.layers.get(OCCUPANCY).map(|l| l.meta)
    }

    /// After occupancy moved to another grid (size, resolution or origin): it is another
    /// world, so the world id becomes the new grid's (its name kept), and every free
    /// layer still on the old grid is forgotten, as a delete does: a layer that covers
    /// other cells than occupancy is nobody's map, and its writer sends it again on the
    /// new grid, for the new world. Nothing happens when the grid is the same.
    fn follow_occupancy_grid(&mut self, before: Option<GridMeta>) -> Result<(), StoreError> {
        let Some(now) = self.get_shared(OCCUPANCY) else {
            return Ok(());
        };
        if before.is_none_or(|b| b == now.meta) {
            return Ok(());
        }
        let stale: Vec<(String, u64)> = self
            .layers
            .values()
            .filter(|l| !BASE_LAYERS.contains(&l.name.as_str()) && l.meta != now.meta)
            .map(|l| (l.name.clone(), l.version))
            .collect();
        for (name, version) in &stale {
            self.forget(name, *version)?;
        }
        if let roam_proto::cells::Cells::I8(cells) = &now.cells {
            let name = self.world.as_ref().map_or("map", |w| w.name.as_str());
            let grid = Grid {
                meta: now.meta,
                cells: cells.clone(),
            };
            let world = roam_world::world_id::world_id(name, &grid);
            tracing::info!(
                world = %world,
                forgotten = ?stale.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(),
                "occupancy moved to a {}x{} grid of {} m: a new world",
                now.meta.width,
                now.meta.height,
                now.meta.resolution
            );
            self.set_world(world)?;
        }
        Ok(())
    }

    /// Removes layer `name` (at `version`) and remembers its version, on disk too.
    fn forget(&mut self, name: &str, version: u64) -> Result<(), StoreError> {
        let mut tombstones = self.tombstones.clone();
        remember(&mut tombstones, name, version);
        if let Some(data) = &mut self.data {
            data.delete(name, &tombstones)?;
        }
        self.tombstones = tombstones;
        self.layers.remove(name);
        self.derivations.remove(name);
        Ok(())
    }

    /// Applies one update to layer `name`. Returns the acknowledgement and how each
    /// changed layer is published (a `set_cells` change as a delta when small).
    pub fn apply(
        &mut self,
        name: &str,
        update: &LayerUpdate,
    ) -> Result<(UpdateAck, Vec<Publication>), StoreError> {
        keys::check_name("layer name", name).map_err(|e| StoreError::Invalid(e.to_string()))?;
        if let (Some(theirs), Some(mine)) = (&update.world, &self.world) {
            if theirs.hash != mine.hash {
                return Err(StoreError::Invalid(format!(
                    "the update of '{name}' was made for world {theirs}, but this map server holds world {mine}: give the writer the same map or scenario"
                )));
            }
        }
        if let Some(source_layer) = derived_source(name) {
            return Err(StoreError::Derived {
                layer: name.to_owned(),
                source_layer: source_layer.to_owned(),
            });
        }
        self.check_base(
            name,
            update.base_version,
            "update",
            "apply your change to it",
        )?;
        let mut pending = Pending::default();
        let before = self.occupancy_meta();
        match &update.change {
            LayerChange::Replace { meta, cells } => {
                check_meta(meta)?;
                self.check_size(meta)?;
                if cells.len() as u64 != meta.cell_count() {
                    return Err(StoreError::Invalid(format!(
                        "the replacement has {} cells but its meta says {}x{} = {}",
                        cells.len(),
                        meta.width,
                        meta.height,
                        meta.cell_count()
                    )));
                }
                if !self.layers.contains_key(name)
                    && self.layers.len() as u64 >= self.limits.max_layers
                {
                    return Err(limit(
                        "max_layers",
                        self.limits.max_layers,
                        self.layers.len() as u64 + 1,
                        "layers held (delete one with <root>/map/delete/<name>)".into(),
                    ));
                }
                self.check_budget(name, &self.sizes_after(name, meta, cells.dtype(), false))?;
                if name == INFORMATION {
                    self.stage_information(&mut pending, *meta, cells.clone())?;
                } else {
                    self.stage_source(&mut pending, name, *meta, cells.clone(), None)?;
                }
            }
            LayerChange::SetCells { cells } => {
                let count = cells.len() as u64;
                if count > self.limits.max_cells_per_update {
                    return Err(limit(
                        "max_cells_per_update",
                        self.limits.max_cells_per_update,
                        count,
                        "cells in one set_cells update".into(),
                    ));
                }
                let layer = self
                    .layers
                    .get(name)
                    .ok_or_else(|| StoreError::NotFound(name.to_owned()))?;
                let edits = CellEdits::from_writes(layer, cells)
                    .map_err(|e| StoreError::Invalid(e.to_string()))?;
                self.stage_cell_edits(&mut pending, name, edits)?;
            }
        }
        let version = pending.version_of(name).unwrap_or(0);
        let changed = self.commit(pending)?;
        if name == OCCUPANCY {
            self.follow_occupancy_grid(before)?;
        }
        let derived = changed
            .iter()
            .map(Publication::name)
            .filter(|&n| n != name)
            .filter_map(|n| self.layers.get(n))
            .map(|l| info(l))
            .collect();
        Ok((
            UpdateAck {
                layer: name.to_owned(),
                version,
                derived,
            },
            changed,
        ))
    }

    /// Deletes free layer `name`, which must be at `base_version`. Its files are
    /// removed and its last version remembered, so a layer created again under the
    /// name goes on from there. The base layers cannot be deleted.
    pub fn delete(&mut self, name: &str, base_version: u64) -> Result<LayerDeleted, StoreError> {
        keys::check_name("layer name", name).map_err(|e| StoreError::Invalid(e.to_string()))?;
        if BASE_LAYERS.contains(&name) {
            let why = match derived_source(name) {
                Some(source) => format!(
                    "it is computed from '{source}' and exists as long as its source, which every stack needs"
                ),
                None => "it is one of the base layers (occupancy, information, inflated, heuristic) every stack needs; change it with an update or a map load instead".into(),
            };
            return Err(StoreError::Protected {
                layer: name.to_owned(),
                why,
            });
        }
        if !self.layers.contains_key(name) {
            return Err(StoreError::NothingToDelete {
                layer: name.to_owned(),
                held: self.names().collect::<Vec<_>>().join(", "),
            });
        }
        self.check_base(
            name,
            base_version,
            "deletion",
            "delete it again if you still mean to",
        )?;
        self.forget(name, base_version)?;
        Ok(LayerDeleted {
            layer: name.to_owned(),
            version: base_version,
        })
    }

    fn check_base(
        &self,
        name: &str,
        base: u64,
        what: &'static str,
        retry: &'static str,
    ) -> Result<(), StoreError> {
        let current = self.version(name);
        if base != current {
            return Err(StoreError::Stale {
                layer: name.to_owned(),
                base,
                current,
                what,
                retry,
            });
        }
        Ok(())
    }

    fn check_size(&self, meta: &GridMeta) -> Result<(), StoreError> {
        let cells = meta.cell_count();
        if cells > self.limits.max_layer_cells {
            return Err(limit(
                "max_layer_cells",
                self.limits.max_layer_cells,
                cells,
                format!("a {}x{} layer has too many cells", meta.width, meta.height),
            ));
        }
        Ok(())
    }
}

/// The names of the layers published.
fn names(publications: &[Publication]) -> Vec<String> {
    publications.iter().map(|p| p.name().to_owned()).collect()
}

/// Records that `name` reached `version`, keeping the newest [`MAX_TOMBSTONES`].
fn remember(tombstones: &mut Vec<Tombstone>, name: &str, version: u64) {
    tombstones.retain(|t| t.name != name);
    tombstones.push(Tombstone {
        name: name.to_owned(),
        version,
    });
    let excess = tombstones.len().saturating_sub(MAX_TOMBSTONES);
    tombstones.drain(..excess);
}

pub fn info(layer: &Layer) -> LayerInfo {
    LayerInfo {
        name: layer.name.clone(),
        version: layer.version,
        meta: layer.meta,
        dtype: layer.cells.dtype(),
        derived_from: layer.derived_from.clone(),
    }
}

fn check_meta(meta: &GridMeta) -> Result<(), StoreError> {
    let o = meta.origin;
    if !(meta.resolution.is_finite() && meta.resolution > 0.0) {
        return Err(StoreError::Invalid(format!(
            "resolution must be a positive number of metres per cell, got {}",
            roam_proto::number(meta.resolution)
        )));
    }
    if !(o.x.is_finite() && o.y.is_finite() && o.yaw.is_finite()) {
        return Err(StoreError::Invalid("the origin must be finite".into()));
    }
    Ok(())
}
