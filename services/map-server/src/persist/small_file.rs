//! The data dir's small JSON files (deleted layers' versions, the world): read whole
//! only when regular and small, written atomically.

use std::fs::{self, File};
use std::io::{Read, Write};
use std::path::Path;

use super::error::PersistError;

/// The file's bytes, `None` when it does not exist; refused (as corrupt) when it is not
/// a regular file of at most `max_bytes`.
pub(crate) fn read(path: &Path, max_bytes: u64) -> Result<Option<Vec<u8>>, PersistError> {
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => {
            return Err(PersistError::Read {
                path: path.to_owned(),
                reason: e.to_string(),
            })
        }
    };
    let meta = file.metadata().map_err(|e| PersistError::Read {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    if !meta.is_file() || meta.len() > max_bytes {
        return Err(PersistError::Corrupt {
            path: path.to_owned(),
            reason: format!("not a regular file of at most {max_bytes} bytes"),
        });
    }
    let mut bytes = Vec::new();
    file.take(max_bytes)
        .read_to_end(&mut bytes)
        .map_err(|e| PersistError::Read {
            path: path.to_owned(),
            reason: e.to_string(),
        })?;
    Ok(Some(bytes))
}

/// Writes `body` atomically: temp file, fsync, rename, fsync the folder.
pub(crate) fn write(path: &Path, body: &[u8]) -> Result<(), PersistError> {
    let tmp = path.with_extension("json.tmp");
    let write_err = |p: &Path, e: std::io::Error| PersistError::Write {
        path: p.to_owned(),
        reason: e.to_string(),
    };
    let mut file = File::create(&tmp).map_err(|e| write_err(&tmp, e))?;
    file.write_all(body).map_err(|e| write_err(&tmp, e))?;
    file.sync_all().map_err(|e| write_err(&tmp, e))?;
    fs::rename(&tmp, path).map_err(|e| write_err(path, e))?;
    if let Some(dir) = path.parent() {
        sync_dir(dir)?;
    }
    Ok(())
}

/// Makes renames and new files in `dir` durable.
pub(crate) fn sync_dir(dir: &Path) -> Result<(), PersistError> {
    File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(|e| PersistError::Write {
            path: dir.to_owned(),
            reason: format!("fsync of the folder failed: {e}"),
        })
}
