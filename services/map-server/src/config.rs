//! The map server's config file (YAML). Every field has a default; unknown fields are
//! refused.
//!
//! ```yaml
//! root: roam                     # key root
//! map: config/maps/depot.yaml    # ROS map.yaml or roam scenario; absent: the built-in world
//! data_dir: /var/lib/roam/map    # persistence; absent: layers live in memory only
//! load_dirs: [/srv/roam/maps]    # where `<root>/map/load` may read; absent: loads are off
//! robot_radius_m: 0.25           # overrides the scenario's
//! heuristic_compression: 0.25    # paper 000 c_h
//! lethal_threshold: 65           # occupancy value from which a cell is an obstacle
//! limits: { max_layer_cells: 16777216, max_cells_per_update: 100000,
//!           max_request_bytes: 100663296, max_layers: 64,
//!           max_total_cell_bytes: 1073741824 }
//! zenoh: { mode: client, connect: { endpoints: ["tcp/router:7447"] } }
//! ```

use std::path::PathBuf;

use roam_runtime::service_config::{ServiceConfig, UnknownFields};
use serde::Deserialize;

use crate::store::Limits;

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct MapServerConfig {
    /// `root`, `instance` and `zenoh`, as every service names them.
    #[serde(flatten)]
    pub service: ServiceConfig,
    pub map: Option<PathBuf>,
    pub data_dir: Option<PathBuf>,
    /// The directories a `<root>/map/load` request may read from (names relative to
    /// them; see [`roam_world::load_dirs`]). Empty: loads from the wire are off.
    pub load_dirs: Vec<PathBuf>,
    pub robot_radius_m: Option<f64>,
    pub heuristic_compression: f64,
    pub lethal_threshold: i8,
    pub limits: Limits,
    /// Refuses a field this config does not name.
    #[serde(flatten)]
    pub unknown: UnknownFields,
}

impl Default for MapServerConfig {
    fn default() -> Self {
        MapServerConfig {
            service: ServiceConfig::default(),
            map: None,
            data_dir: None,
            load_dirs: Vec::new(),
            robot_radius_m: None,
            heuristic_compression: 0.25,
            lethal_threshold: 65,
            limits: Limits::default(),
            unknown: UnknownFields,
        }
    }
}
