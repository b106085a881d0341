//! Reading a map file the map server is pointed at: a ROS `map.yaml` (it has an
//! `image:` key) or a roam scenario.

use std::path::{Path, PathBuf};

use roam_proto::{ErrorCode, ErrorReply};

use roam_proto::map::WorldId;

use roam_world::grid::Grid;
use roam_world::load_dirs::{Access, LoadDirs, LoadRefused};
use roam_world::ros_map::{self, RosMapError};
use roam_world::scenario::{self, ScenarioError};
use roam_world::world_id::world_id;

/// What a map file gives the map server.
#[derive(Debug, Clone)]
pub struct MapContent {
    /// Which world this map is ([`roam_world::world_id`]).
    pub world: WorldId,
    pub occupancy: Grid<i8>,
    pub information: Option<Grid<u8>>,
    pub robot_radius_m: Option<f64>,
}

#[derive(Debug, thiserror::Error)]
pub enum MapFileError {
    #[error(transparent)]
    Ros(#[from] RosMapError),
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Refused(LoadRefused),
}

impl MapFileError {
    /// The error reply to a peer's load of `requested`: refusals name the file as the
    /// peer gave it, and every other message names files relative to their load
    /// directory, so the reply holds none of the server's absolute paths (its log,
    /// given the error itself, keeps them).
    pub fn to_reply(&self, requested: &str, dirs: &LoadDirs) -> ErrorReply {
        let message = dirs.redact(&self.to_string());
        match self {
            MapFileError::Refused(refused)
            | MapFileError::Ros(RosMapError::Refused(refused))
            | MapFileError::Scenario(ScenarioError::Refused(refused))
            | MapFileError::Scenario(ScenarioError::Map {
                source: RosMapError::Refused(refused),
                ..
            }) => refused.to_reply(requested),
            MapFileError::Ros(RosMapError::Missing { .. })
            | MapFileError::Scenario(ScenarioError::Missing { .. })
            | MapFileError::Scenario(ScenarioError::Map {
                source: RosMapError::Missing { .. },
                ..
            }) => ErrorReply::new(ErrorCode::NotFound, message),
            MapFileError::Ros(RosMapError::TooLarge { max, actual, .. })
            | MapFileError::Scenario(ScenarioError::Map {
                source: RosMapError::TooLarge { max, actual, .. },
                ..
            }) => ErrorReply::limit("max_layer_cells", *max, *actual, message),
            MapFileError::Ros(RosMapError::Io { .. })
            | MapFileError::Scenario(ScenarioError::Io { .. }) => {
                ErrorReply::new(ErrorCode::Internal, message)
            }
            _ => ErrorReply::new(ErrorCode::CorruptFile, message),
        }
    }
}

/// Reads the map file a load request names: only inside the load directories, and only
/// following references that stay inside them ([`LoadDirs`]).
pub fn read_requested(
    requested: &str,
    dirs: &LoadDirs,
    max_cells: u64,
) -> Result<MapContent, MapFileError> {
    let path = dirs.resolve(requested).map_err(MapFileError::Refused)?;
    read_with(&path, max_cells, Access::Within(dirs))
}

/// Reads a ROS map or a scenario the operator named, telling them apart by the ROS
/// `image:` key.
pub fn read(path: &Path, max_cells: u64) -> Result<MapContent, MapFileError> {
    read_with(path, max_cells, Access::Anywhere)
}

fn read_with(path: &Path, max_cells: u64, access: Access<'_>) -> Result<MapContent, MapFileError> {
    let is_ros = ros_map::read_bounded_text(path)
        .ok()
        .and_then(|text| serde_yaml_ng::from_str::<serde_yaml_ng::Value>(&text).ok())
        .is_some_and(|v| v.get("image").is_some());
    if is_ros {
        let map = ros_map::load_with(path, max_cells, access)?;
        let stem = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        return Ok(MapContent {
            world: world_id(&stem, &map.grid),
            occupancy: map.grid,
            information: None,
            robot_radius_m: None,
        });
    }
    let scenario = scenario::load_with(path, max_cells, access)?;
    Ok(from_scenario(scenario))
}

/// The built-in world.
pub fn builtin(max_cells: u64) -> Result<MapContent, MapFileError> {
    let scenario = scenario::parse(
        &PathBuf::from(scenario::BUILTIN_NAME),
        scenario::BUILTIN,
        max_cells,
    )?;
    Ok(from_scenario(scenario))
}

fn from_scenario(scenario: scenario::Scenario) -> MapContent {
    MapContent {
        world: world_id(&scenario.file.name, &scenario.occupancy),
        occupancy: scenario.occupancy,
        information: Some(scenario.information),
        robot_radius_m: scenario.file.robot_radius_m,
    }
}
