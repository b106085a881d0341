//! The layer store: every layer with its version, the rules for changing them, and
//! the derived layers kept in step. Plain Rust, no network: the Zenoh adapter in
//! [`crate::service`] turns messages into calls on it.
//!
//! Layers:
//! - `occupancy` (i8, ROS values) and `information` (u8, scores 0–100) are sources;
//! - `inflated` (from occupancy, robot radius) and `heuristic` (from information,
//!   compression c_h) are derived and recomputed whenever their source changes;
//! - any other name (`change_rate`, `peb`, ...) is a free layer that its writer owns.
//!
//! Every change names the version it was based on; a stale one is refused. Changes are
//! persisted before they become visible, so a reply never acknowledges what a restart
//! would lose.

use std::collections::BTreeMap;

use roam_proto::cells::Cells;
use roam_proto::map::{
    CellWrite, GridMeta, Layer, LayerChange, LayerInfo, LayerList, LayerUpdate, UpdateAck,
};
use roam_proto::{keys, ErrorCode, ErrorReply};

use crate::grid::{occupancy, Grid};
use crate::layers;
use crate::persist::{DataDir, PersistError};

pub const OCCUPANCY: &str = "occupancy";
pub const INFLATED: &str = "inflated";
pub const INFORMATION: &str = "information";
pub const HEURISTIC: &str = "heuristic";

/// Size limits. Each is named in the error that enforces it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Limits {
    /// Cells in one layer (default 16,777,216 = 4096²; a 1 km² site at 0.25 m).
    pub max_layer_cells: u64,
    /// Cells written by one `set_cells` update.
    pub max_cells_per_update: u64,
    /// Bytes of one request payload.
    pub max_request_bytes: u64,
    /// Layers held at once.
    pub max_layers: u64,
}

pub const DEFAULT_LIMITS: Limits = Limits {
    max_layer_cells: 16_777_216,
    max_cells_per_update: 100_000,
    max_request_bytes: 96 * 1024 * 1024,
    max_layers: 64,
};

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

/// Why a change was refused.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("layer '{layer}' is at version {current}, but the update was based on version {base}; get the latest layer and apply your change to it")]
    Stale {
        layer: String,
        base: u64,
        current: u64,
    },
    #[error("layer '{layer}' is computed from '{source_layer}'; update '{source_layer}' instead")]
    Derived { layer: String, source_layer: String },
    #[error("layer '{0}' does not exist; create it with a replace based on version 0")]
    NotFound(String),
    #[error("{0}")]
    Invalid(String),
    #[error("{message}")]
    Limit {
        name: &'static str,
        max: u64,
        actual: u64,
        message: String,
    },
    #[error("the change could not be persisted, so it was not applied: {0}")]
    Persist(#[from] PersistError),
}

impl StoreError {
    pub fn to_reply(&self) -> ErrorReply {
        let message = self.to_string();
        match self {
            StoreError::Stale { .. } => ErrorReply::new(ErrorCode::StaleVersion, message),
            StoreError::Derived { .. } | StoreError::Invalid(_) => {
                ErrorReply::new(ErrorCode::InvalidRequest, message)
            }
            StoreError::NotFound(_) => ErrorReply::new(ErrorCode::NotFound, message),
            StoreError::Limit {
                name, max, actual, ..
            } => ErrorReply::limit(name, *max, *actual, message),
            StoreError::Persist(_) => ErrorReply::new(ErrorCode::Internal, message),
        }
    }
}

fn limit(name: &'static str, max: u64, actual: u64, what: String) -> StoreError {
    StoreError::Limit {
        name,
        max,
        actual,
        message: format!("{what}: {actual} is over the limit {name} = {max}"),
    }
}

/// The map server's layers.
#[derive(Debug)]
pub struct LayerStore {
    layers: BTreeMap<String, Layer>,
    limits: Limits,
    derived: DerivedParams,
    data: Option<DataDir>,
    warnings: Vec<String>,
}

impl LayerStore {
    pub fn new(limits: Limits, derived: DerivedParams, data: Option<DataDir>) -> Self {
        LayerStore {
            layers: BTreeMap::new(),
            limits,
            derived,
            data,
            warnings: Vec::new(),
        }
    }

    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// Changes the robot radius used for `inflated` from the next occupancy change on.
    pub fn set_robot_radius(&mut self, radius_m: f64) {
        self.derived.robot_radius_m = radius_m;
    }

    /// Loads the persisted layers. Returns whether any were found.
    pub fn restore(&mut self) -> bool {
        let Some(data) = &self.data else { return false };
        let loaded = data.load_all();
        for warning in &loaded.warnings {
            tracing::error!("{warning}");
        }
        self.warnings.extend(loaded.warnings);
        let found = !loaded.layers.is_empty();
        for layer in loaded.layers {
            self.layers.insert(layer.name.clone(), layer);
        }
        found
    }

    pub fn get(&self, name: &str) -> Option<&Layer> {
        self.layers.get(name)
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.layers.keys().map(String::as_str)
    }

    pub fn version(&self, name: &str) -> u64 {
        self.layers.get(name).map_or(0, |l| l.version)
    }

    /// Every layer's info, and the warnings found while restoring.
    pub fn list(&self) -> LayerList {
        LayerList {
            layers: self.layers.values().map(info).collect(),
            warnings: self.warnings.clone(),
        }
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
            self.check_base(OCCUPANCY, base)?;
        }
        self.check_size(&occupancy_grid.meta)?;
        let mut pending = Pending::default();
        let info_cells = information.map(|g| Cells::U8(g.cells));
        self.stage_source(
            &mut pending,
            OCCUPANCY,
            occupancy_grid.meta,
            Cells::I8(occupancy_grid.cells),
            info_cells,
        )?;
        self.commit(pending)
    }

    /// Applies one update to layer `name`.
    pub fn apply(
        &mut self,
        name: &str,
        update: &LayerUpdate,
    ) -> Result<(UpdateAck, Vec<String>), StoreError> {
        keys::check_name("layer name", name).map_err(|e| StoreError::Invalid(e.to_string()))?;
        if let Some(source_layer) = derived_source(name) {
            return Err(StoreError::Derived {
                layer: name.to_owned(),
                source_layer: source_layer.to_owned(),
            });
        }
        self.check_base(name, update.base_version)?;
        let mut pending = Pending::default();
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
                        "layers held".into(),
                    ));
                }
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
                let mut new_cells = layer.cells.clone();
                for write in cells {
                    set_cell(name, &layer.meta, &mut new_cells, write)?;
                }
                let meta = layer.meta;
                if name == INFORMATION {
                    self.stage_information(&mut pending, meta, new_cells)?;
                } else {
                    self.stage_source(&mut pending, name, meta, new_cells, None)?;
                }
            }
        }
        let version = pending.version_of(name).unwrap_or(0);
        let changed = self.commit(pending)?;
        let derived = changed
            .iter()
            .filter(|n| n.as_str() != name)
            .filter_map(|n| self.layers.get(n))
            .map(info)
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

    fn check_base(&self, name: &str, base: u64) -> Result<(), StoreError> {
        let current = self.version(name);
        if base != current {
            return Err(StoreError::Stale {
                layer: name.to_owned(),
                base,
                current,
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

    /// Stages a new source layer and what follows from it: `inflated` for occupancy,
    /// and an information map resized to a new occupancy size.
    fn stage_source(
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
            let grid = Grid {
                meta,
                cells: values.clone(),
            };
            let inflated = layers::inflate(
                &grid,
                self.derived.robot_radius_m,
                self.derived.lethal_threshold,
            );
            pending.put(self, name, meta, None, cells);
            pending.put(
                self,
                INFLATED,
                meta,
                Some(OCCUPANCY),
                Cells::I8(inflated.cells),
            );
            let info_meta = self.layers.get(INFORMATION).map(|l| l.meta);
            match information {
                Some(info) => self.stage_information(pending, meta, info)?,
                None if info_meta != Some(meta) => {
                    // The information map must cover the same cells as occupancy.
                    let zeros = Cells::U8(vec![0; meta.cell_count() as usize]);
                    self.stage_information_unchecked(pending, meta, zeros);
                }
                None => {}
            }
            return Ok(());
        }
        if let Some(bad) = not_a_number(&cells) {
            return Err(StoreError::Invalid(format!(
                "layer '{name}' cells must be numbers (infinity is allowed), got {bad}"
            )));
        }
        pending.put(self, name, meta, None, cells);
        Ok(())
    }

    fn stage_information(
        &self,
        pending: &mut Pending,
        meta: GridMeta,
        cells: Cells,
    ) -> Result<(), StoreError> {
        let Cells::U8(values) = &cells else {
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
        self.stage_information_unchecked(pending, meta, cells);
        Ok(())
    }

    fn stage_information_unchecked(&self, pending: &mut Pending, meta: GridMeta, cells: Cells) {
        if let Cells::U8(values) = &cells {
            let grid = Grid {
                meta,
                cells: values.clone(),
            };
            let heuristic = layers::heuristic(&grid, self.derived.heuristic_compression);
            pending.put(
                self,
                HEURISTIC,
                heuristic.meta,
                Some(INFORMATION),
                Cells::F32(heuristic.cells),
            );
        }
        pending.put(self, INFORMATION, meta, None, cells);
    }

    /// Persists then installs the staged layers; returns their names.
    fn commit(&mut self, pending: Pending) -> Result<Vec<String>, StoreError> {
        if let Some(data) = &self.data {
            for layer in &pending.layers {
                data.save(layer)?;
            }
        }
        let names = pending.layers.iter().map(|l| l.name.clone()).collect();
        for layer in pending.layers {
            self.layers.insert(layer.name.clone(), layer);
        }
        Ok(names)
    }
}

/// Layers staged by one change, installed together.
#[derive(Default)]
struct Pending {
    layers: Vec<Layer>,
}

impl Pending {
    fn put(
        &mut self,
        store: &LayerStore,
        name: &str,
        meta: GridMeta,
        derived_from: Option<&str>,
        cells: Cells,
    ) {
        self.layers.retain(|l| l.name != name);
        self.layers.push(Layer {
            name: name.to_owned(),
            version: store.version(name) + 1,
            meta,
            derived_from: derived_from.map(str::to_owned),
            cells,
        });
    }

    fn meta_of(&self, name: &str) -> Option<GridMeta> {
        self.layers.iter().find(|l| l.name == name).map(|l| l.meta)
    }

    fn version_of(&self, name: &str) -> Option<u64> {
        self.layers
            .iter()
            .find(|l| l.name == name)
            .map(|l| l.version)
    }
}

/// The source of a derived layer.
pub fn derived_source(name: &str) -> Option<&'static str> {
    match name {
        INFLATED => Some(OCCUPANCY),
        HEURISTIC => Some(INFORMATION),
        _ => None,
    }
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
            meta.resolution
        )));
    }
    if !(o.x.is_finite() && o.y.is_finite() && o.yaw.is_finite()) {
        return Err(StoreError::Invalid("the origin must be finite".into()));
    }
    Ok(())
}

/// The first NaN of an f32 layer. Infinity is a value (an unbounded PEB, say); NaN is
/// never one.
fn not_a_number(cells: &Cells) -> Option<f32> {
    match cells {
        Cells::F32(v) => v.iter().copied().find(|c| c.is_nan()),
        _ => None,
    }
}

/// Writes one cell, checking its position and its value against the layer's type.
fn set_cell(
    name: &str,
    meta: &GridMeta,
    cells: &mut Cells,
    write: &CellWrite,
) -> Result<(), StoreError> {
    if write.x >= meta.width || write.y >= meta.height {
        return Err(StoreError::Invalid(format!(
            "cell ({}, {}) is outside layer '{name}' ({}x{}); x is the column 0..{}, y the row 0..{}",
            write.x, write.y, meta.width, meta.height, meta.width, meta.height
        )));
    }
    let index = write.y as usize * meta.width as usize + write.x as usize;
    let value = write.value;
    let (lo, hi) = match (name, &*cells) {
        (OCCUPANCY, _) => (-1.0, 100.0),
        (INFORMATION, _) => (0.0, 100.0),
        (_, Cells::I8(_)) => (-128.0, 127.0),
        (_, Cells::U8(_)) => (0.0, 255.0),
        (_, Cells::F32(_)) => (f64::from(f32::MIN), f64::from(f32::MAX)),
    };
    let rounded = if matches!(cells, Cells::F32(_)) {
        value
    } else {
        value.round()
    };
    if !(rounded.is_finite() && (lo..=hi).contains(&rounded)) {
        return Err(StoreError::Invalid(format!(
            "value {value} at ({}, {}) is outside {lo}..={hi} for layer '{name}'",
            write.x, write.y
        )));
    }
    match cells {
        Cells::I8(v) => v[index] = rounded as i8,
        Cells::U8(v) => v[index] = rounded as u8,
        Cells::F32(v) => v[index] = rounded as f32,
    }
    Ok(())
}
