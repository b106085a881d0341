//! Layers on disk: one file per layer in `<data_dir>/layers/`, written atomically, with
//! the previous good copy kept beside it.
//!
//! File format (`<name>.layer`): one line of JSON header
//! `{"format": "roam-layer", "v": 1, "name", "version", "meta", "dtype", "derived_from", "bytes", "crc32"}`
//! then exactly `bytes` bytes of cells (little-endian, row-major) whose CRC-32 is `crc32`.
//! Binary cells keep a 1.7-million-cell layer at 1.7 MB and its write at a few ms.
//!
//! Saving: write `<name>.layer.tmp`, fsync it, hard-link the current file to
//! `<name>.layer.prev`, rename the tmp file over `<name>.layer`, fsync the folder. A
//! crash at any point leaves a complete `<name>.layer` or `<name>.layer.prev`.
//!
//! Loading: a file that is truncated, fails its CRC or has a bad header is reported
//! (naming the file), moved aside to `<name>.layer.corrupt` so nothing is lost, and the
//! `.prev` copy is used when it is good.

use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

use roam_proto::cells::{Cells, Dtype};
use roam_proto::map::{GridMeta, Layer};
use serde::{Deserialize, Serialize};

const FORMAT: &str = "roam-layer";
const FORMAT_VERSION: u32 = 1;
const MAX_HEADER_BYTES: usize = 64 * 1024;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    format: String,
    v: u32,
    name: String,
    version: u64,
    meta: GridMeta,
    dtype: Dtype,
    #[serde(default)]
    derived_from: Option<String>,
    bytes: u64,
    crc32: u32,
}

/// Why a layer file could not be written or read. Each variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum PersistError {
    #[error("cannot write {path}: {reason}")]
    Write { path: PathBuf, reason: String },
    #[error("cannot read {path}: {reason}")]
    Read { path: PathBuf, reason: String },
    #[error("{path} is corrupt: {reason}")]
    Corrupt { path: PathBuf, reason: String },
}

/// The data directory of a map server.
#[derive(Debug, Clone)]
pub struct DataDir {
    layers: PathBuf,
}

/// What loading the data directory found.
#[derive(Debug, Default)]
pub struct Loaded {
    pub layers: Vec<Layer>,
    /// One sentence per problem: corrupt files, fallbacks to the previous copy.
    pub warnings: Vec<String>,
}

impl DataDir {
    /// Opens (and creates) `<root>/layers`.
    pub fn open(root: &Path) -> Result<Self, PersistError> {
        let layers = root.join("layers");
        fs::create_dir_all(&layers).map_err(|e| PersistError::Write {
            path: layers.clone(),
            reason: e.to_string(),
        })?;
        Ok(DataDir { layers })
    }

    /// The file a layer is stored in.
    pub fn path_of(&self, name: &str) -> PathBuf {
        self.layers.join(format!("{name}.layer"))
    }

    /// Writes a layer atomically, keeping the previous copy as `.prev`.
    pub fn save(&self, layer: &Layer) -> Result<(), PersistError> {
        let path = self.path_of(&layer.name);
        let tmp = path.with_extension("layer.tmp");
        let prev = path.with_extension("layer.prev");
        let write_err = |p: &Path, e: std::io::Error| PersistError::Write {
            path: p.to_owned(),
            reason: e.to_string(),
        };
        let body = layer.cells.to_le_bytes();
        let header = Header {
            format: FORMAT.into(),
            v: FORMAT_VERSION,
            name: layer.name.clone(),
            version: layer.version,
            meta: layer.meta,
            dtype: layer.cells.dtype(),
            derived_from: layer.derived_from.clone(),
            bytes: body.len() as u64,
            crc32: crc32fast::hash(&body),
        };
        let mut header_line = serde_json::to_vec(&header).map_err(|e| PersistError::Write {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        header_line.push(b'\n');
        {
            let mut file = File::create(&tmp).map_err(|e| write_err(&tmp, e))?;
            file.write_all(&header_line)
                .map_err(|e| write_err(&tmp, e))?;
            file.write_all(&body).map_err(|e| write_err(&tmp, e))?;
            file.sync_all().map_err(|e| write_err(&tmp, e))?;
        }
        if path.exists() {
            let _ = fs::remove_file(&prev);
            fs::hard_link(&path, &prev).map_err(|e| write_err(&prev, e))?;
        }
        fs::rename(&tmp, &path).map_err(|e| write_err(&path, e))?;
        if let Ok(dir) = File::open(&self.layers) {
            let _ = dir.sync_all();
        }
        Ok(())
    }

    /// Loads every layer. Never fails as a whole: each bad file becomes a warning.
    pub fn load_all(&self) -> Loaded {
        let mut loaded = Loaded::default();
        let entries = match fs::read_dir(&self.layers) {
            Ok(entries) => entries,
            Err(e) => {
                loaded
                    .warnings
                    .push(format!("cannot list {}: {e}", self.layers.display()));
                return loaded;
            }
        };
        let mut names: Vec<String> = entries
            .filter_map(Result::ok)
            .filter_map(|e| e.file_name().into_string().ok())
            .filter_map(|f| {
                f.strip_suffix(".layer")
                    .or_else(|| f.strip_suffix(".layer.prev"))
                    .map(str::to_owned)
            })
            .collect();
        names.sort();
        names.dedup();
        for name in names {
            match self.load_one(&name, &mut loaded.warnings) {
                Some(layer) => loaded.layers.push(layer),
                None => loaded.warnings.push(format!(
                    "layer '{name}' has no readable copy and was not loaded"
                )),
            }
        }
        loaded
    }

    fn load_one(&self, name: &str, warnings: &mut Vec<String>) -> Option<Layer> {
        let path = self.path_of(name);
        let prev = path.with_extension("layer.prev");
        if path.exists() {
            match read_layer(&path) {
                Ok(layer) => return Some(layer),
                Err(e) => {
                    let aside = path.with_extension("layer.corrupt");
                    let kept = match fs::rename(&path, &aside) {
                        Ok(()) => format!("kept as {}", aside.display()),
                        Err(r) => format!("could not move it aside ({r})"),
                    };
                    warnings.push(format!("{e}; {kept}"));
                }
            }
        }
        match read_layer(&prev) {
            Ok(layer) => {
                warnings.push(format!(
                    "layer '{name}' restored from the last good copy {} (version {})",
                    prev.display(),
                    layer.version
                ));
                Some(layer)
            }
            Err(e) => {
                if prev.exists() {
                    warnings.push(e.to_string());
                }
                None
            }
        }
    }
}

/// Reads and checks one layer file.
pub fn read_layer(path: &Path) -> Result<Layer, PersistError> {
    let bytes = fs::read(path).map_err(|e| PersistError::Read {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    let corrupt = |reason: String| PersistError::Corrupt {
        path: path.to_owned(),
        reason,
    };
    let newline = bytes
        .iter()
        .take(MAX_HEADER_BYTES)
        .position(|&b| b == b'\n')
        .ok_or_else(|| corrupt("no header line".into()))?;
    let header: Header = serde_json::from_slice(&bytes[..newline])
        .map_err(|e| corrupt(format!("bad header: {e}")))?;
    if header.format != FORMAT || header.v != FORMAT_VERSION {
        return Err(corrupt(format!("not a {FORMAT} v{FORMAT_VERSION} file")));
    }
    let body = &bytes[newline + 1..];
    if body.len() as u64 != header.bytes {
        return Err(corrupt(format!(
            "truncated: {} of {} cell bytes",
            body.len(),
            header.bytes
        )));
    }
    if crc32fast::hash(body) != header.crc32 {
        return Err(corrupt("cell bytes fail their CRC-32".into()));
    }
    let cells = Cells::from_le_bytes(header.dtype, body)
        .ok_or_else(|| corrupt("cell bytes are not whole cells".into()))?;
    if cells.len() as u64 != header.meta.cell_count() {
        return Err(corrupt(format!(
            "{} cells for a {}x{} grid",
            cells.len(),
            header.meta.width,
            header.meta.height
        )));
    }
    Ok(Layer {
        name: header.name,
        version: header.version,
        meta: header.meta,
        derived_from: header.derived_from,
        cells,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    fn layer(version: u64, fill: i8) -> Layer {
        Layer {
            name: "occupancy".into(),
            version,
            meta: GridMeta {
                width: 4,
                height: 3,
                resolution: 0.05,
                origin: Origin::default(),
            },
            derived_from: None,
            cells: Cells::I8(vec![fill; 12]),
        }
    }

    #[test]
    fn saved_layers_load_back() {
        let dir = tempfile::tempdir().expect("tmp");
        let data = DataDir::open(dir.path()).expect("open");
        data.save(&layer(1, 0)).expect("save");
        data.save(&layer(2, 100)).expect("save");
        let loaded = data.load_all();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        assert_eq!(loaded.layers, vec![layer(2, 100)]);
    }

    #[test]
    fn a_truncated_file_falls_back_to_the_previous_copy_and_is_kept() {
        let dir = tempfile::tempdir().expect("tmp");
        let data = DataDir::open(dir.path()).expect("open");
        data.save(&layer(1, 0)).expect("save");
        data.save(&layer(2, 100)).expect("save");
        let path = data.path_of("occupancy");
        let bytes = fs::read(&path).expect("read");
        fs::write(&path, &bytes[..bytes.len() - 3]).expect("truncate");
        let loaded = data.load_all();
        assert_eq!(loaded.layers, vec![layer(1, 0)]);
        let all = loaded.warnings.join("\n");
        assert!(
            all.contains("occupancy.layer is corrupt: truncated"),
            "{all}"
        );
        assert!(all.contains("last good copy"), "{all}");
        assert!(path.with_extension("layer.corrupt").exists());
    }

    #[test]
    fn a_flipped_byte_fails_the_crc() {
        let dir = tempfile::tempdir().expect("tmp");
        let data = DataDir::open(dir.path()).expect("open");
        data.save(&layer(1, 0)).expect("save");
        let path = data.path_of("occupancy");
        let mut bytes = fs::read(&path).expect("read");
        let last = bytes.len() - 1;
        bytes[last] ^= 0x40;
        fs::write(&path, bytes).expect("write");
        let err = read_layer(&path).expect_err("must be refused");
        assert!(err.to_string().contains("CRC-32"), "{err}");
        let loaded = data.load_all();
        assert!(loaded.layers.is_empty());
        assert!(loaded
            .warnings
            .iter()
            .any(|w| w.contains("no readable copy")));
    }
}
