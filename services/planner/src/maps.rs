//! The maps the planner plans on: the latest `inflated` and `information` layers from
//! the map server, and a few earlier versions for requests that name one.

use std::collections::VecDeque;
use std::sync::Arc;

use roam_map_server::grid::Grid;
use roam_proto::cells::Cells;
use roam_proto::map::Layer;
use roam_proto::planner::MapVersion;

use crate::world::World;

/// The layer names the planner reads.
pub const INFLATED: &str = "inflated";
pub const INFORMATION: &str = "information";
/// Localization's PEB layer: the localizability cost's input (`w_loc`).
pub const PEB: &str = "peb";

/// Heuristic compression the cached worlds are built with (Table I); requests with
/// another c_h get their blocks recut.
pub const DEFAULT_COMPRESSION: f64 = 0.25;

/// Latest layers and the worlds built from them.
#[derive(Debug, Default)]
pub struct MapCache {
    inflated: Option<Layer>,
    information: Option<Layer>,
    peb: Option<Layer>,
    worlds: VecDeque<(MapVersion, Arc<World>)>,
    history: usize,
    /// The layer taken as the information map.
    information_layer: String,
}

impl MapCache {
    pub fn new(history: usize) -> Self {
        MapCache::with_information(history, INFORMATION)
    }

    /// A cache that takes `information_layer` (a u8 layer) as the information map.
    pub fn with_information(history: usize, information_layer: &str) -> Self {
        MapCache {
            history: history.max(1),
            information_layer: information_layer.to_owned(),
            ..MapCache::default()
        }
    }

    /// The layer names this cache follows.
    pub fn layers(&self) -> [&str; 3] {
        [INFLATED, self.information_layer.as_str(), PEB]
    }

    /// Takes a new layer; rebuilds the world when both layers are present and agree in
    /// size. Returns the new version when a world was built.
    pub fn update(&mut self, layer: Layer) -> Option<MapVersion> {
        if layer.name == PEB {
            self.take_peb(layer);
            return None;
        }
        let slot = match layer.name.as_str() {
            INFLATED => &mut self.inflated,
            name if name == self.information_layer => &mut self.information,
            _ => return None,
        };
        if slot
            .as_ref()
            .is_some_and(|old| old.version >= layer.version)
        {
            return None;
        }
        *slot = Some(layer);
        let (Some(inflated), Some(information)) = (&self.inflated, &self.information) else {
            return None;
        };
        let version = MapVersion {
            inflated: inflated.version,
            information: information.version,
        };
        if self.worlds.iter().any(|(v, _)| *v == version) {
            return None;
        }
        let (Cells::I8(occ), Cells::U8(info)) = (&inflated.cells, &information.cells) else {
            tracing::warn!("the map server's layers have unexpected types; not planning on them");
            return None;
        };
        let occ = Grid {
            meta: inflated.meta,
            cells: occ.clone(),
        };
        let info = Grid {
            meta: information.meta,
            cells: info.clone(),
        };
        match World::new(&occ, &info, DEFAULT_COMPRESSION) {
            Ok(mut world) => {
                if let Some(c) = world.clamped {
                    let (x, y, score) = c.first;
                    tracing::warn!(
                        layer = %self.information_layer,
                        version = information.version,
                        cells = c.cells,
                        "information layer has {} cells scored above {}, the first at cell ({x}, {y}) with {score}; they count as {} (fix the layer, or plan on a 0..=100 layer)",
                        c.cells,
                        crate::world::MAX_INFORMATION_SCORE,
                        crate::world::MAX_INFORMATION_SCORE,
                    );
                }
                if let Some(Cells::F32(peb)) = self.peb.as_ref().map(|l| &l.cells) {
                    world.set_localizability(peb);
                }
                self.worlds.push_back((version, Arc::new(world)));
                while self.worlds.len() > self.history {
                    self.worlds.pop_front();
                }
                Some(version)
            }
            Err(e) => {
                tracing::warn!("cannot plan on map {version:?}: {e}");
                None
            }
        }
    }

    /// Takes a newer PEB layer and gives every cached world its localizability cost
    /// (a world of another size gets none).
    fn take_peb(&mut self, layer: Layer) {
        if self
            .peb
            .as_ref()
            .is_some_and(|old| old.version >= layer.version)
        {
            return;
        }
        let Cells::F32(peb) = &layer.cells else {
            return tracing::warn!("the PEB layer is not f32 cells; no localizability cost");
        };
        for (_, world) in self.worlds.iter_mut() {
            let mut w = World::clone(world);
            w.set_localizability(peb);
            *world = Arc::new(w);
        }
        self.peb = Some(layer);
    }

    /// The world for a version, or the latest.
    pub fn world(&self, version: Option<MapVersion>) -> Option<(MapVersion, Arc<World>)> {
        match version {
            None => self.worlds.back().cloned(),
            Some(v) => self.worlds.iter().find(|(k, _)| *k == v).cloned(),
        }
    }

    pub fn versions(&self) -> Vec<MapVersion> {
        self.worlds.iter().map(|(v, _)| *v).collect()
    }
}
