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
pub(crate) struct Mapping {
    /// The world the layers are of, sent with their updates.
    pub(crate) world: roam_proto::map::WorldId,
    /// Its grid.
    pub(crate) meta: GridMeta,
    /// Its static occupancy: the map now's prior for cells never seen.
    pub(crate) static_map: Grid<i8>,
    pub(crate) map: ChangeMap,
    /// The robots' reservations (their current missions).
    pub(crate) news: NewsMap,
    /// Each robot's last observed position, where its mission's path starts; kept for
    /// the first [`MAX_RESERVING_ROBOTS`] robots heard (a mission of any other starts at
    /// its first waypoint).
    pub(crate) positions: BTreeMap<String, [f64; 2]>,
    pub(crate) explorers: BTreeMap<String, Explorer>,
    /// The exploration goal last published per robot: a goal is published when it changes.
    pub(crate) published_goals: BTreeMap<String, ExplorationGoal>,
    pub(crate) observations: u64,
    pub(crate) map_changes: u64,
    pub(crate) features: (f64, f64),
    /// Mapper time ([`Epochs`]) of the newest observation.
    pub(crate) now_s: f64,
    /// Something was observed since the layers were last sent.
    pub(crate) dirty: bool,
    pub(crate) layers_sent: u64,
    /// Observation times against the sim clock; resets as epochs.
    pub(crate) epochs: Epochs,
}

/// What the mapper's subscribers, publisher and queryable share: the session and the
/// mapping under its lock.
pub(crate) struct MapperShared {
    pub(crate) root: String,
    pub(crate) session: zenoh::Session,
    pub(crate) mapping: Mutex<Mapping>,
    /// What a world's mapping is made of, for the world the map server moves to.
    pub(crate) spec: MappingSpec,
    /// Refused observations, logged a few per key and window.
    pub(crate) warnings: WarnLimiter,
    pub(crate) belief: BeliefParams,
    /// How far a robot sees along its mission's path, metres, and how fast it drives it.
    pub(crate) reserve_radius_m: f64,
    pub(crate) reserve_s_per_m: f64,
}

/// What a world's mapping is made of besides its grid.
pub(crate) struct MappingSpec {
    pub(crate) map: MapParams,
    pub(crate) news: NewsParams,
    pub(crate) explorer: ExplorerParams,
    pub(crate) seed: u64,
    pub(crate) explore: BTreeSet<String>,
}

impl MappingSpec {
    /// A fresh mapping of `world`, whose static occupancy is `static_map`.
    pub(crate) fn build(
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
    pub(crate) fn mapping(&self) -> MutexGuard<'_, Mapping> {
        roam_runtime::lock(&self.mapping)
    }

    /// Commands, goals and statuses are state a robot must not miss: delivered.
    pub(crate) fn put<T: Message>(&self, key: &str, message: &T) {
        roam_runtime::publish_wait(&self.session, key, message, Delivery::Reliable);
    }
}
