//! The last version of each deleted layer, `<data_dir>/deleted-layers.json`, so that a
//! layer created again under the same name goes on from there: a follower that keeps
//! the newest version takes the new layer, and a writer still holding a version of the
//! deleted one is refused as stale instead of writing into the new one.
//!
//! `{"format": "roam-deleted-layers", "v": 1, "layers": [{"name", "version"}, ...]}`,
//! oldest first, at most [`MAX_TOMBSTONES`] entries: a name deleted longer ago than the
//! last 256 deletions starts again at version 1.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::error::PersistError;
use super::small_file;
use super::snapshot::describe_json_error;

const FORMAT: &str = "roam-deleted-layers";
const FORMAT_VERSION: u32 = 1;
/// Deleted layers remembered.
pub const MAX_TOMBSTONES: usize = 256;
/// The largest file read: 256 entries of a 64-character name and a 20-digit version fit
/// in well under this.
const MAX_FILE_BYTES: u64 = 256 * 1024;

/// A deleted layer and the version it had.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tombstone {
    pub name: String,
    pub version: u64,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TombstoneFile {
    format: String,
    v: u32,
    layers: Vec<Tombstone>,
}

/// Reads the tombstones; a missing file is none.
pub fn read(path: &Path) -> Result<Vec<Tombstone>, PersistError> {
    let corrupt = |reason: String| PersistError::Corrupt {
        path: path.to_owned(),
        reason,
    };
    let Some(bytes) = small_file::read(path, MAX_FILE_BYTES)? else {
        return Ok(Vec::new());
    };
    let parsed: TombstoneFile =
        serde_json::from_slice(&bytes).map_err(|e| corrupt(describe_json_error(&e)))?;
    if parsed.format != FORMAT || parsed.v != FORMAT_VERSION {
        return Err(corrupt(format!("not a {FORMAT} v{FORMAT_VERSION} file")));
    }
    if parsed
        .layers
        .iter()
        .any(|t| roam_proto::keys::check_name("layer name", &t.name).is_err())
    {
        return Err(corrupt("an entry names no valid layer".into()));
    }
    Ok(parsed.layers)
}

/// Writes the tombstones atomically, keeping the newest [`MAX_TOMBSTONES`].
pub fn write(path: &Path, tombstones: &[Tombstone]) -> Result<(), PersistError> {
    let keep = &tombstones[tombstones.len().saturating_sub(MAX_TOMBSTONES)..];
    let body = serde_json::to_vec(&TombstoneFile {
        format: FORMAT.into(),
        v: FORMAT_VERSION,
        layers: keep.to_vec(),
    })
    .map_err(|e| PersistError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    small_file::write(path, &body)
}
