//! Restoring the store from its data dir, with three guarantees:
//!
//! 1. **Derived layers are in step with their sources.** A derived layer whose
//!    derivation names another source version (a crash between the two saves, a source
//!    restored from an older copy), another recipe (the config's radius changed) or no
//!    version at all (a file of an older map server), or that has no readable copy, is
//!    computed again from its source.
//! 2. **Versions never go back.** A layer restored from an older copy than the files
//!    show it reached (a fallback to `.prev`, a gap in the log) is served under a version
//!    above every one seen, so followers that keep the newest version take it, and a
//!    writer holding a lost version is refused as stale. A lost layer's last version is
//!    remembered, so a layer sent again goes on from there.
//! 3. **No source is missing.** A source with no readable copy is reported in
//!    [`Restored::lost_sources`]; the service loads the configured map again for it
//!    ([`LayerStore::reload_lost_sources`]). Until then its derived layer is not served.
//!
//! Whatever restore changed is persisted before the store serves anything, so readers
//! only ever see the reconciled layers.

use std::collections::BTreeMap;
use std::sync::Arc;

use roam_proto::cells::Cells;
use roam_proto::map::Layer;

use super::pending::{Change, Pending, Staged};
use super::{
    derived_source, names, remember, LayerStore, StoreError, HEURISTIC, INFLATED, INFORMATION,
    OCCUPANCY,
};
use crate::derived::{Derivation, Recipe};
use roam_world::grid::Grid;

/// What a restore found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Restored {
    /// Whether the data dir held any layer file (readable or not). When it held none,
    /// the service loads its configured map as a fresh start.
    pub found: bool,
    /// Sources (`occupancy`, `information`) with no usable copy, to load from the
    /// configured map again.
    pub lost_sources: Vec<&'static str>,
}

const SOURCES: [&str; 2] = [OCCUPANCY, INFORMATION];

impl LayerStore {
    /// Loads the persisted layers and reconciles them (see the module docs). Unless
    /// `radius_from_config`, the robot radius `inflated` was computed with is kept.
    pub fn restore(&mut self, radius_from_config: bool) -> Result<Restored, StoreError> {
        let Some(data) = &mut self.data else {
            return Ok(Restored::default());
        };
        let loaded = data.load_all();
        let world = data.load_world();
        for warning in loaded.warnings {
            self.warn(warning);
        }
        match world {
            Ok(world) => self.world = world,
            Err(e) => self.warn(format!("{e}; the world the layers are of is unknown")),
        }
        self.tombstones = loaded.tombstones;
        let mut highest: BTreeMap<String, u64> = BTreeMap::new();
        let mut rewrite = Vec::new();
        let mut lost = Vec::new();
        for recovered in loaded.layers {
            highest.insert(recovered.name.clone(), recovered.highest_seen);
            match recovered.layer {
                Some((layer, derivation)) => {
                    if recovered.rewrite {
                        rewrite.push(layer.name.clone());
                    }
                    if let Some(d) = derivation {
                        self.derivations.insert(layer.name.clone(), d);
                    }
                    self.layers.insert(layer.name.clone(), Arc::new(layer));
                }
                None => lost.push(recovered.name),
            }
        }
        // A derived layer tells how far its source got.
        for derived in [INFLATED, HEURISTIC] {
            if let (Some(d), Some(source)) =
                (self.derivations.get(derived), derived_source(derived))
            {
                let h = highest.entry(source.to_owned()).or_default();
                *h = (*h).max(d.source_version);
            }
        }
        let mut restored = Restored {
            found: loaded.found,
            lost_sources: Vec::new(),
        };
        self.check_information_fits(&mut lost);
        for source in SOURCES {
            if !self.layers.contains_key(source) && loaded.found {
                restored.lost_sources.push(source);
            }
        }
        // Remember lost layers' versions, so what replaces them goes on from there.
        let mut tombstones = self.tombstones.clone();
        for name in &lost {
            let version = highest.get(name).copied().unwrap_or(0);
            if version > 0 {
                remember(&mut tombstones, name, version);
            }
            if !SOURCES.contains(&name.as_str()) && derived_source(name).is_none() {
                self.warn(format!(
                    "layer '{name}' could not be restored; its writer must send it again (a replace based on version 0, which makes version {})",
                    version + 1
                ));
            }
        }
        // A derived layer without its source is not served.
        for derived in [INFLATED, HEURISTIC] {
            let source = derived_source(derived).unwrap_or_default();
            if !self.layers.contains_key(source) {
                if let Some(layer) = self.layers.remove(derived) {
                    remember(
                        &mut tombstones,
                        derived,
                        layer
                            .version
                            .max(highest.get(derived).copied().unwrap_or(0)),
                    );
                }
                self.derivations.remove(derived);
            }
        }
        if tombstones != self.tombstones {
            self.tombstones = tombstones;
            if let Some(data) = &self.data {
                data.save_tombstones(&self.tombstones)?;
            }
        }
        let mut pending = Pending::default();
        self.stage_reversioned(&mut pending, &highest);
        if !radius_from_config {
            if let Some(Derivation {
                recipe: Recipe::Inflate { robot_radius_m, .. },
                ..
            }) = self.derivations.get(INFLATED)
            {
                self.derived.robot_radius_m = *robot_radius_m;
            }
        }
        self.stage_derived_in_step(&mut pending, &highest);
        for name in rewrite {
            if pending.version_of(&name).is_none() {
                if let Some(layer) = self.layers.get(&name) {
                    pending.put(Staged {
                        name: name.clone(),
                        version: layer.version,
                        derivation: self.derivations.get(&name).copied(),
                        change: Change::Full(Layer::clone(layer)),
                    });
                }
            }
        }
        self.commit(pending)?;
        let held = self.held_cell_bytes();
        if held > self.limits.max_total_cell_bytes {
            self.warn(format!(
                "the restored layers hold {held} bytes of cells, over the limit max_total_cell_bytes = {}: they are all served, but a replace or a load that adds to them is refused until layers are deleted",
                self.limits.max_total_cell_bytes
            ));
        }
        Ok(restored)
    }

    /// An information map that does not fit the restored occupancy grid (occupancy came
    /// back from an older copy of another size) cannot be kept.
    fn check_information_fits(&mut self, lost: &mut Vec<String>) {
        let (Some(occ), Some(info)) = (self.layers.get(OCCUPANCY), self.layers.get(INFORMATION))
        else {
            return;
        };
        if occ.meta == info.meta {
            return;
        }
        self.warn(format!(
            "the restored information map ({}x{}) does not fit the restored occupancy grid ({}x{}); it is loaded again",
            info.meta.width, info.meta.height, occ.meta.width, occ.meta.height
        ));
        self.layers.remove(INFORMATION);
        lost.push(INFORMATION.to_owned());
    }

    /// Layers that came back at a lower version than the files show they reached are
    /// served above it.
    fn stage_reversioned(&mut self, pending: &mut Pending, highest: &BTreeMap<String, u64>) {
        let mut warnings = Vec::new();
        for (name, layer) in &self.layers {
            let seen = highest.get(name).copied().unwrap_or(0);
            if seen <= layer.version || derived_source(name).is_some() {
                // Derived layers are computed again below, above their own versions.
                continue;
            }
            let version = seen + 1;
            warnings.push(format!(
                "layer '{name}': the changes that made versions {} to {seen} could not be restored; its last good content (version {}) is served as version {version}, so followers take it and writers holding a lost version are refused",
                layer.version + 1,
                layer.version
            ));
            let mut content = Layer::clone(layer);
            content.version = version;
            pending.put(Staged {
                name: name.clone(),
                version,
                derivation: None,
                change: Change::Full(content),
            });
        }
        for w in warnings {
            self.warn(w);
        }
    }

    /// Computes again every derived layer that is not in step with its source (as it
    /// is once `pending` is installed).
    fn stage_derived_in_step(&mut self, pending: &mut Pending, highest: &BTreeMap<String, u64>) {
        let mut warnings = Vec::new();
        for derived in [INFLATED, HEURISTIC] {
            let Some(source) = derived_source(derived) else {
                continue;
            };
            let Some(src) = self.layers.get(source) else {
                continue;
            };
            let source_version = pending.version_of(source).unwrap_or(src.version);
            let recipe = match derived {
                INFLATED => self.derived.inflate(),
                _ => self.derived.heuristic(),
            };
            let Some(why) = self.out_of_step(derived, source_version, recipe) else {
                continue;
            };
            let floor = highest
                .get(derived)
                .copied()
                .unwrap_or(0)
                .max(self.version(derived));
            let before = pending.staged.len();
            match &src.cells {
                Cells::I8(v) if derived == INFLATED => {
                    self.stage_inflated(pending, src.meta, v.clone(), source_version)
                }
                Cells::U8(v) if derived == HEURISTIC => {
                    self.stage_heuristic(pending, src.meta, v.clone(), source_version)
                }
                _ => continue,
            }
            // Above every version the layer had, not only the one it came back with,
            // and never below its source's (a derived layer changes with its source,
            // so without evidence of its own that is how far it got).
            if pending.staged.len() > before {
                if let Some(staged) = pending.staged.last_mut() {
                    let version = staged.version.max(floor + 1).max(source_version);
                    staged.version = version;
                    if let Change::Full(layer) = &mut staged.change {
                        layer.version = version;
                    }
                    warnings.push(format!(
                        "layer '{derived}' computed again from '{source}' version {source_version}, as version {version}: {why}"
                    ));
                }
            }
        }
        for w in warnings {
            self.warn(w);
        }
    }

    /// Why derived layer `name` is not what `recipe` makes of source version
    /// `source_version`, or `None` when it is.
    fn out_of_step(&self, name: &str, source_version: u64, recipe: Recipe) -> Option<String> {
        let Some(layer) = self.layers.get(name) else {
            return Some("it had no readable copy".into());
        };
        let Some(d) = self.derivations.get(name) else {
            return Some(format!(
                "its file (version {}) does not say which source version it was computed from",
                layer.version
            ));
        };
        if d.source_version != source_version {
            return Some(format!(
                "it was computed from version {} (its source changed after it was saved: a crash between their saves, or a source restored from an older copy)",
                d.source_version
            ));
        }
        if d.recipe != recipe {
            return Some(format!(
                "it was computed with {}, the config now asks for {}",
                describe(&d.recipe),
                describe(&recipe)
            ));
        }
        None
    }

    /// Loads `lost` sources (from [`Restored::lost_sources`]) from the configured map
    /// `map_name`: its occupancy grid, and its information map where it fits (else
    /// zeros). A source that was restored is kept when it fits. Returns the changed
    /// layers.
    pub fn reload_lost_sources(
        &mut self,
        occupancy_grid: Grid<i8>,
        information: Option<Grid<u8>>,
        lost: &[&str],
        map_name: &str,
    ) -> Result<Vec<String>, StoreError> {
        let mut pending = Pending::default();
        if lost.contains(&OCCUPANCY) {
            self.check_size(&occupancy_grid.meta)?;
            let meta = occupancy_grid.meta;
            let keep_info = !lost.contains(&INFORMATION)
                && self.layers.get(INFORMATION).is_some_and(|i| i.meta == meta);
            let info = information
                .filter(|g| g.meta == meta && !keep_info)
                .map(|g| Cells::U8(g.cells));
            self.stage_source(
                &mut pending,
                OCCUPANCY,
                meta,
                Cells::I8(occupancy_grid.cells),
                info,
            )?;
        } else if lost.contains(&INFORMATION) {
            let Some(meta) = self.layers.get(OCCUPANCY).map(|l| l.meta) else {
                return Ok(Vec::new());
            };
            let cells = information
                .filter(|g| g.meta == meta)
                .map_or_else(|| vec![0; meta.cell_count() as usize], |g| g.cells);
            self.stage_information(&mut pending, meta, Cells::U8(cells))?;
        }
        let mut warnings = Vec::new();
        for source in lost {
            if let Some(version) = pending.version_of(source) {
                warnings.push(format!(
                    "layer '{source}' had no readable copy in the data dir: the configured map {map_name} was loaded again, as version {version}"
                ));
            }
        }
        let changed = self.commit(pending)?;
        for w in warnings {
            self.warn(w);
        }
        Ok(names(&changed))
    }
}

fn describe(recipe: &Recipe) -> String {
    match recipe {
        Recipe::Inflate {
            robot_radius_m,
            lethal_threshold,
        } => format!("robot radius {robot_radius_m} m and lethal threshold {lethal_threshold}"),
        Recipe::Heuristic { compression } => format!("compression {compression}"),
    }
}
