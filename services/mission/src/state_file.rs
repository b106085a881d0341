//! What the executive keeps on disk across its restarts (its calibration, the route it
//! drives) is written and read the same way: written to `<file>.tmp`, synced and
//! renamed over `<file>`, so a crash mid-write leaves the previous one whole; read only
//! up to a size limit, so a file replaced by something huge costs nothing.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically, making its folder if needed; why not.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let io = |e: std::io::Error| e.to_string();
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    {
        let mut out = std::fs::File::create(&tmp).map_err(io)?;
        out.write_all(bytes).map_err(io)?;
        out.sync_all().map_err(io)?;
    }
    std::fs::rename(&tmp, path).map_err(io)
}

/// The bytes of `path`; `None` when there is no file; why it cannot be read (not a
/// regular file, beyond `max_bytes`, named `limit` in the reason).
pub fn read_bounded(path: &Path, max_bytes: u64, limit: &str) -> Result<Option<Vec<u8>>, String> {
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e.to_string()),
    };
    if !meta.is_file() {
        return Err("not a regular file".into());
    }
    if meta.len() > max_bytes {
        return Err(format!(
            "{} bytes is beyond {max_bytes} ({limit})",
            meta.len()
        ));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(max_bytes + 1).read_to_end(&mut bytes))
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > max_bytes {
        return Err(format!("beyond {max_bytes} bytes ({limit})"));
    }
    Ok(Some(bytes))
}
