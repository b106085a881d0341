//! What the mapper's subscribers, publisher and queryable share: one world's mapping
//! under a lock, and how to build it afresh for another world.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Mutex, MutexGuard};

use roam_proto::map::GridMeta;
use roam_proto::mapper::ExplorationGoal;
use roam_proto::Message;
use roam_runtime::warn_limit::WarnLimiter;
use roam_runtime::Delivery;
use roam_world::epoch::Epochs;
use roam_world::grid::Grid;

use crate::belief::BeliefParams;
use crate::change_map::{ChangeMap, MapParams};
use crate::explorer::{Explorer, ExplorerParams, Mode};
use crate::news::{NewsMap, NewsParams};

use super::config::MapperServiceError;

/// What observations and missions change, on one world's grid.
pub(super) struct Mapping {
    /// The world the layers are of, sent with their updates.
    pub(super) world: roam_proto::map::WorldId,
    /// Its grid.
    pub(super) meta: GridMeta,
    /// Its static occupancy: the map now's prior for cells never seen.
    pub(super) static_map: Grid<i8>,
    pub(super) map: ChangeMap,
    /// The robots' reservations (their current missions).
    pub(super) news: NewsMap,
    /// Each robot's last observed position, where its mission's path starts; kept for
    /// the first [`MAX_RESERVING_ROBOTS`] robots heard (a mission of any other starts at
    /// its first waypoint).
    pub(super) positions: BTreeMap<String, [f64; 2]>,
    pub(super) explorers: BTreeMap<String, Explorer>,
    /// The exploration goal last published per robot: a goal is published when it changes.
    pub(super) published_goals: BTreeMap<String, ExplorationGoal>,
    pub(super) observations: u64,
    pub(super) map_changes: u64,
    pub(super) features: (f64, f64),
    /// Mapper time ([`Epochs`]) of the newest observation.
    pub(super) now_s: f64,
    /// Something was observed since the layers were last sent.
    pub(super) dirty: bool,
    pub(super) layers_sent: u64,
    /// Observation times against the sim clock; resets as epochs.
    pub(super) epochs: Epochs,
}

/// What the mapper's subscribers, publisher and queryable share: the session and the
/// mapping under its lock.
pub(super) struct MapperShared {
    pub(super) root: String,
    pub(super) session: zenoh::Session,
    pub(super) mapping: Mutex<Mapping>,
    /// What a world's mapping is made of, for the world the map server moves to.
    pub(super) spec: MappingSpec,
    /// Refused observations, logged a few per key and window.
    pub(super) warnings: WarnLimiter,
    pub(super) belief: BeliefParams,
    /// How far a robot sees along its mission's path, metres, and how fast it drives it.
    pub(super) reserve_radius_m: f64,
    pub(super) reserve_s_per_m: f64,
}

/// What a world's mapping is made of besides its grid.
pub(super) struct MappingSpec {
    pub(super) map: MapParams,
    pub(super) news: NewsParams,
    pub(super) explorer: ExplorerParams,
    pub(super) seed: u64,
    pub(super) explore: BTreeSet<String>,
}

impl MappingSpec {
    /// A fresh mapping of `world`, whose static occupancy is `static_map`.
    pub(super) fn build(
        &self,
        world: roam_proto::map::WorldId,
        static_map: Grid<i8>,
    ) -> Result<Mapping, MapperServiceError> {
        let meta = static_map.meta;
        let config = |e: crate::error::MapperError| MapperServiceError::Config(e.to_string());
        let explorers = self
            .explore
            .iter()
            .map(|robot| {
                // Seeded by the robot's name, not its place in the list: a robot explores
                // the same way whichever other robots are explored beside it.
                let seed = crate::seed::labelled(self.seed, &format!("explore/{robot}"));
                Explorer::new(self.explorer, Mode::Curious, seed)
                    .map(|e| (robot.clone(), e))
                    .map_err(config)
            })
            .collect::<Result<_, _>>()?;
        Ok(Mapping {
            world,
            meta,
            static_map,
            map: ChangeMap::new(meta, self.map).map_err(config)?,
            news: NewsMap::new(meta, self.news.prior).map_err(config)?,
            positions: BTreeMap::new(),
            explorers,
            published_goals: BTreeMap::new(),
            observations: 0,
            map_changes: 0,
            features: (0.0, 0.0),
            now_s: 0.0,
            // Sent at once: the layers exist at the map's size before the first
            // observation, so a planner on the change coupling has one to plan on.
            dirty: true,
            layers_sent: 0,
            epochs: Epochs::default(),
        })
    }
}

impl MapperShared {
    pub(super) fn mapping(&self) -> MutexGuard<'_, Mapping> {
        roam_runtime::lock(&self.mapping)
    }

    /// Commands, goals and statuses are state a robot must not miss: delivered.
    pub(super) fn put<T: Message>(&self, key: &str, message: &T) {
        roam_runtime::publish_wait(&self.session, key, message, Delivery::Reliable);
    }
}
