//! The world the layers are of, `<data_dir>/world.json`: a map server restored from its
//! data dir still knows which map it holds, so services given another can be told.
//!
//! `{"format": "roam-world", "v": 1, "world": {"name", "hash"}}`.

use std::path::Path;

use roam_proto::map::WorldId;
use serde::{Deserialize, Serialize};

use super::error::PersistError;
use super::small_file;
use super::snapshot::describe_json_error;

const FORMAT: &str = "roam-world";
const FORMAT_VERSION: u32 = 1;
const MAX_FILE_BYTES: u64 = 4 * 1024;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldFile {
    format: String,
    v: u32,
    world: WorldId,
}

/// The recorded world; `None` when none was recorded.
pub fn read(path: &Path) -> Result<Option<WorldId>, PersistError> {
    let Some(bytes) = small_file::read(path, MAX_FILE_BYTES)? else {
        return Ok(None);
    };
    let corrupt = |reason: String| PersistError::Corrupt {
        path: path.to_owned(),
        reason,
    };
    let parsed: WorldFile =
        serde_json::from_slice(&bytes).map_err(|e| corrupt(describe_json_error(&e)))?;
    if parsed.format != FORMAT || parsed.v != FORMAT_VERSION {
        return Err(corrupt(format!("not a {FORMAT} v{FORMAT_VERSION} file")));
    }
    Ok(Some(parsed.world))
}

/// Records the world atomically.
pub fn write(path: &Path, world: &WorldId) -> Result<(), PersistError> {
    let body = serde_json::to_vec(&WorldFile {
        format: FORMAT.into(),
        v: FORMAT_VERSION,
        world: world.clone(),
    })
    .map_err(|e| PersistError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    small_file::write(path, &body)
}
