//! The maps the planner plans on: the latest `inflated` and `information` layers from
//! the map server (and, on a planner that couples one, the mapper's change layer; see
//! [`crate::coupling`]), and a few earlier versions for requests that name one.

use std::collections::VecDeque;
use std::sync::Arc;

use roam_proto::cells::Cells;
use roam_proto::layer_delta::LayerDelta;
use roam_proto::map::Layer;
use roam_proto::planner::MapVersion;
use roam_world::grid::Grid;

use crate::coupling::{self, Coupling};
use crate::resolution::PAPER_RESOLUTION_M;
use crate::world::{World, WorldError};

/// The layer names the planner reads.
pub use roam_proto::map::{INFLATED_LAYER as INFLATED, INFORMATION_LAYER as INFORMATION};
/// Localization's PEB layer: the localizability cost's input (`w_loc`).
pub const PEB: &str = "peb";

/// Heuristic compression the cached worlds are built with (Table I); requests with
/// another c_h get their blocks recut.
pub const DEFAULT_COMPRESSION: f64 = 0.25;

/// What a delta did to the cache ([`MapCache::apply_delta`]).
#[derive(Debug, Clone, PartialEq)]
pub enum DeltaOutcome {
    /// Applied; the version of the world built from it, when one was.
    Applied(Option<MapVersion>),
    /// The cache holds the delta's version or a later one already.
    Held,
    /// A layer the cache does not follow.
    NotFollowed,
    /// The delta does not apply to what the cache holds (it missed a delta, holds
    /// nothing of the layer yet, or the delta does not fit the layer; the reason says
    /// which): the whole layer is needed.
    Gap(String),
}

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
    /// The change layer coupled into the information map, if any, and its latest.
    change_layer: Option<String>,
    change: Option<Layer>,
    /// How it is coupled ([`crate::coupling`]), and the news product's floor ε.
    coupling: Coupling,
    news_floor: f64,
    /// The layer of what the fleet has seen, planned around ([`crate::seen`]), if any,
    /// its latest, and how far its obstacles are inflated, metres.
    obstacles_layer: Option<String>,
    obstacles: Option<Layer>,
    obstacle_inflation_m: f64,
    /// The planning resolution ([`crate::resolution`]); `None`: paper 000's 0.2 m, or
    /// the map's resolution where that is coarser.
    planning_resolution_m: Option<f64>,
    /// Why the latest layers gave no world, when they did not.
    last_error: Option<WorldError>,
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

    /// This cache with `change_layer` (a u8 layer of scores 0–100, the mapper's
    /// `change_information`) coupled into the information map ([`crate::coupling`]).
    pub fn coupling_change(mut self, change_layer: Option<&str>) -> Self {
        self.change_layer = change_layer.map(str::to_owned);
        self
    }

    /// This cache coupling its change layer by `rule` (default [`Coupling::Max`]), the
    /// news product with the floor `news_floor` ([`crate::coupling::news_product`]).
    pub fn coupled_by(mut self, rule: Coupling, news_floor: f64) -> Self {
        self.coupling = rule;
        self.news_floor = news_floor;
        self
    }

    /// This cache planning at `planning_resolution_m` (see the field).
    pub fn planning_at(mut self, planning_resolution_m: Option<f64>) -> Self {
        self.planning_resolution_m = planning_resolution_m;
        self
    }

    /// This cache planning around what `layer` (the mapper's `occupied_now`) believes
    /// occupied, inflated by `inflation_m` ([`crate::seen`]).
    pub fn avoiding_seen(mut self, layer: Option<&str>, inflation_m: f64) -> Self {
        self.obstacles_layer = layer.map(str::to_owned);
        self.obstacle_inflation_m = inflation_m;
        self
    }

    /// The planning resolution for a map of `map_resolution` metres.
    pub fn planning_resolution(&self, map_resolution: f64) -> f64 {
        self.planning_resolution_m
            .unwrap_or(PAPER_RESOLUTION_M.max(map_resolution))
    }

    /// Why the latest layers gave no world (e.g. a planning resolution finer than the
    /// map's), if they did not.
    pub fn last_error(&self) -> Option<&WorldError> {
        self.last_error.as_ref()
    }

    /// The layer names this cache follows.
    pub fn layers(&self) -> Vec<String> {
        let mut names = vec![INFLATED, self.information_layer.as_str(), PEB];
        names.extend(self.change_layer.as_deref());
        names.extend(self.obstacles_layer.as_deref());
        names.into_iter().map(str::to_owned).collect()
    }

    /// Takes a delta of a followed layer: applied to the layer held when that is the
    /// delta's base version (then as [`MapCache::update`] takes a layer). A delta of a
    /// layer not followed, or one the cache already has (the version held is the
    /// delta's or later), changes nothing.
    pub fn apply_delta(&mut self, delta: &LayerDelta) -> DeltaOutcome {
        let slot = match delta.name.as_str() {
            PEB => &mut self.peb,
            INFLATED => &mut self.inflated,
            name if name == self.information_layer => &mut self.information,
            name if Some(name) == self.change_layer.as_deref() => &mut self.change,
            name if Some(name) == self.obstacles_layer.as_deref() => &mut self.obstacles,
            _ => return DeltaOutcome::NotFollowed,
        };
        let Some(mut layer) = slot.take() else {
            return DeltaOutcome::Gap(format!("no version of '{}' held yet", delta.name));
        };
        if layer.version >= delta.version {
            *slot = Some(layer);
            return DeltaOutcome::Held;
        }
        match delta.apply(&mut layer) {
            Ok(()) => DeltaOutcome::Applied(self.update(layer)),
            Err(e) => {
                *slot = Some(layer);
                DeltaOutcome::Gap(e.to_string())
            }
        }
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
            name if Some(name) == self.change_layer.as_deref() => &mut self.change,
            name if Some(name) == self.obstacles_layer.as_deref() => &mut self.obstacles,
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
        if let Some(change) = &self.change {
            if coupling::usable(change, information).is_none() {
                tracing::warn!(
                    layer = %change.name,
                    version = change.version,
                    "the change layer is not u8 scores on the information layer's grid; planning on {} alone",
                    self.information_layer
                );
            }
        }
        let change = self
            .change
            .as_ref()
            .and_then(|c| coupling::usable(c, information));
        let obstacles = self
            .obstacles
            .as_ref()
            .filter(|o| o.meta == inflated.meta && matches!(o.cells, Cells::I8(_)));
        let version = MapVersion {
            inflated: inflated.version,
            information: information.version,
            change: change.map(|c| c.version),
            obstacles: obstacles.map(|o| o.version),
        };
        if self.worlds.iter().any(|(v, _)| *v == version) {
            return None;
        }
        let (Cells::I8(occ), Cells::U8(info)) = (&inflated.cells, &information.cells) else {
            tracing::warn!("the map server's layers have unexpected types; not planning on them");
            return None;
        };
        let mut occ = Grid {
            meta: inflated.meta,
            cells: occ.clone(),
        };
        if let Some(seen) = obstacles {
            crate::seen::block_seen(&mut occ, seen, self.obstacle_inflation_m);
        }
        let info = Grid {
            meta: information.meta,
            cells: match change.map(|c| &c.cells) {
                Some(Cells::U8(scores)) => self.coupling.apply(info, scores, self.news_floor),
                _ => info.clone(),
            },
        };
        let planning = self.planning_resolution(inflated.meta.resolution);
        match World::at_resolution(&occ, &info, DEFAULT_COMPRESSION, planning) {
            Ok(mut world) => {
                self.last_error = None;
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
                self.last_error = Some(e);
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};

    /// A one-row layer of `cells.len()` cells.
    pub(crate) fn layer(name: &str, version: u64, cells: Cells) -> Layer {
        let width = cells.len() as u32;
        Layer {
            name: name.to_owned(),
            version,
            derived_from: None,
            meta: GridMeta {
                width,
                height: 1,
                resolution: 0.2,
                origin: Origin {
                    x: 0.0,
                    y: 0.0,
                    yaw: 0.0,
                },
            },
            cells,
        }
    }

    #[test]
    fn a_coupled_cache_plans_on_the_static_map_until_change_arrives_then_on_the_maximum() {
        let mut cache = MapCache::new(4).coupling_change(Some("change_information"));
        assert_eq!(
            cache.layers(),
            [INFLATED, INFORMATION, PEB, "change_information"].map(str::to_owned)
        );
        cache.update(layer(INFLATED, 1, Cells::I8(vec![0; 4])));
        let first = cache
            .update(layer(INFORMATION, 1, Cells::U8(vec![10, 20, 30, 40])))
            .expect("a world once both layers are in");
        assert_eq!(first.change, None);
        let (_, world) = cache.world(None).expect("world");
        assert_eq!(world.information, vec![10, 20, 30, 40]);

        let coupled = cache
            .update(layer(
                "change_information",
                3,
                Cells::U8(vec![90, 0, 35, 0]),
            ))
            .expect("a new world for the change layer");
        assert_eq!(coupled.change, Some(3));
        let (_, world) = cache.world(None).expect("world");
        assert_eq!(world.information, vec![90, 20, 35, 40]);
        // The static world stays for requests that name it.
        assert_eq!(cache.world(Some(first)).map(|(v, _)| v), Some(first));
    }

    #[test]
    fn a_cache_coupled_by_the_news_product_plans_on_interest_times_news() {
        let mut cache = MapCache::new(4)
            .coupling_change(Some("news"))
            .coupled_by(Coupling::News, crate::coupling::DEFAULT_NEWS_FLOOR);
        cache.update(layer(INFLATED, 1, Cells::I8(vec![0; 4])));
        cache.update(layer(INFORMATION, 1, Cells::U8(vec![10, 20, 30, 40])));
        let coupled = cache
            .update(layer("news", 2, Cells::U8(vec![100, 0, 50, 25])))
            .expect("a new world for the news layer");
        assert_eq!(coupled.change, Some(2));
        let (_, world) = cache.world(None).expect("world");
        // The weights ε + (1 − ε) · N / 100 at ε = 0.25 are 1, 0.25, 0.625, 0.4375, so
        // I · w = 10, 5, 18.75, 17.5, the best (18.75) worth the best interest (40).
        assert_eq!(world.information, vec![21, 11, 40, 37]);
    }

    #[test]
    fn a_delta_at_the_held_version_makes_a_new_world_and_any_other_asks_for_the_layer() {
        use roam_proto::layer_delta::CellPositions;
        let mut cache = MapCache::new(4);
        let delta = |base: u64, x: u32, value: u8| LayerDelta {
            name: INFORMATION.into(),
            base_version: base,
            version: base + 1,
            positions: CellPositions(vec![(x, 0)]),
            values: Cells::U8(vec![value]),
        };
        assert!(matches!(
            cache.apply_delta(&delta(1, 0, 50)),
            DeltaOutcome::Gap(_)
        ));
        cache.update(layer(INFLATED, 1, Cells::I8(vec![0; 4])));
        cache.update(layer(INFORMATION, 1, Cells::U8(vec![1; 4])));
        let outcome = cache.apply_delta(&delta(1, 2, 50));
        let DeltaOutcome::Applied(Some(version)) = outcome else {
            panic!("a new world expected, got {outcome:?}");
        };
        assert_eq!(version.information, 2);
        let (_, world) = cache.world(None).expect("world");
        assert_eq!(world.information, vec![1, 1, 50, 1]);
        assert_eq!(cache.apply_delta(&delta(1, 2, 60)), DeltaOutcome::Held);
        assert!(matches!(
            cache.apply_delta(&delta(3, 0, 60)),
            DeltaOutcome::Gap(_)
        ));
        // A delta that does not fit (a cell outside the layer) changes nothing.
        assert!(matches!(
            cache.apply_delta(&delta(2, 9, 60)),
            DeltaOutcome::Gap(_)
        ));
        assert_eq!(cache.versions().last().map(|v| v.information), Some(2));
        let other = LayerDelta {
            name: "recency".into(),
            ..delta(1, 0, 1)
        };
        assert_eq!(cache.apply_delta(&other), DeltaOutcome::NotFollowed);
    }

    #[test]
    fn an_uncoupled_cache_ignores_the_change_layer() {
        let mut cache = MapCache::new(4);
        assert_eq!(
            cache.layers(),
            [INFLATED, INFORMATION, PEB].map(str::to_owned)
        );
        cache.update(layer(INFLATED, 1, Cells::I8(vec![0; 4])));
        cache.update(layer(INFORMATION, 1, Cells::U8(vec![1; 4])));
        assert_eq!(
            cache.update(layer("change_information", 1, Cells::U8(vec![99; 4]))),
            None
        );
    }
}
