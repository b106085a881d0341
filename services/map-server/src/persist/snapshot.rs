//! Snapshot files: one whole layer, `<name>.layer`.
//!
//! One line of JSON header, then exactly `bytes` bytes of cells (little-endian,
//! row-major) whose CRC-32 is `crc32`:
//! `{"format": "roam-layer", "v": 2, "name", "version", "meta", "dtype", "derived_from"?,
//! "derivation"?, "bytes", "crc32"}`. `derivation` (v2) says which source version and
//! recipe a derived layer was computed from; v1 files (without it) are still read.
//!
//! Reading checks the file before it allocates anything for it: a regular file, no
//! larger than the largest layer `max_layer_cells` allows, a header that names this
//! very layer, a cell count within the limit and a body of exactly the header's size.
//! Errors name the file and give a short reason or a line and column, never the file's
//! content.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;

use roam_proto::cells::{Cells, Dtype};
use roam_proto::keys;
use roam_proto::map::{GridMeta, Layer};
use serde::{Deserialize, Serialize};

use super::error::PersistError;
use crate::derived::Derivation;

const FORMAT: &str = "roam-layer";
/// The version written; 1 is still read.
const FORMAT_VERSION: u32 = 2;
/// The longest header line read.
pub const MAX_HEADER_BYTES: u64 = 64 * 1024;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    format: String,
    v: u32,
    name: String,
    version: u64,
    meta: GridMeta,
    dtype: Dtype,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    derived_from: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    derivation: Option<Derivation>,
    bytes: u64,
    crc32: u32,
}

/// A snapshot read back and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    pub layer: Layer,
    pub derivation: Option<Derivation>,
    /// The file's size in bytes.
    pub file_bytes: u64,
}

/// A snapshot that could not be used, and the version its header claimed when the
/// header could be read and named this layer (evidence that the layer reached it).
#[derive(Debug)]
pub struct Unreadable {
    pub error: PersistError,
    pub version_seen: Option<u64>,
}

/// The largest snapshot file a layer of at most `max_layer_cells` cells can need: four
/// bytes a cell (f32) and the header line.
pub fn max_file_bytes(max_layer_cells: u64) -> u64 {
    max_layer_cells
        .saturating_mul(4)
        .saturating_add(MAX_HEADER_BYTES)
}

/// Writes `layer` to `path` and fsyncs it; returns the file's size.
pub fn write(
    path: &Path,
    layer: &Layer,
    derivation: Option<&Derivation>,
) -> Result<u64, PersistError> {
    let write_err = |e: std::io::Error| PersistError::Write {
        path: path.to_owned(),
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
        derivation: derivation.copied(),
        bytes: body.len() as u64,
        crc32: crc32fast::hash(&body),
    };
    let mut line = serde_json::to_vec(&header).map_err(|e| PersistError::Write {
        path: path.to_owned(),
        reason: format!("the header does not serialize: {e}"),
    })?;
    line.push(b'\n');
    let mut file = File::create(path).map_err(write_err)?;
    file.write_all(&line).map_err(write_err)?;
    file.write_all(&body).map_err(write_err)?;
    file.sync_all().map_err(write_err)?;
    Ok((line.len() + body.len()) as u64)
}

/// Reads and checks the snapshot of layer `name` at `path`.
pub fn read(path: &Path, name: &str, max_layer_cells: u64) -> Result<Snapshot, Unreadable> {
    let corrupt = |reason: String| PersistError::Corrupt {
        path: path.to_owned(),
        reason,
    };
    let fail = |error: PersistError| Unreadable {
        error,
        version_seen: None,
    };
    let file = File::open(path).map_err(|e| {
        fail(PersistError::Read {
            path: path.to_owned(),
            reason: e.to_string(),
        })
    })?;
    let file_bytes = file
        .metadata()
        .map_err(|e| {
            fail(PersistError::Read {
                path: path.to_owned(),
                reason: e.to_string(),
            })
        })?
        .len();
    check_regular_and_small(path, &file, file_bytes, max_layer_cells).map_err(fail)?;
    let mut reader = BufReader::new(file);
    let mut line = Vec::new();
    (&mut reader)
        .take(MAX_HEADER_BYTES)
        .read_until(b'\n', &mut line)
        .map_err(|e| {
            fail(PersistError::Read {
                path: path.to_owned(),
                reason: e.to_string(),
            })
        })?;
    if line.pop() != Some(b'\n') {
        return Err(fail(corrupt(format!(
            "no header line in its first {MAX_HEADER_BYTES} bytes"
        ))));
    }
    let header: Header = serde_json::from_slice(&line)
        .map_err(|e| fail(corrupt(format!("bad header: {}", describe_json_error(&e)))))?;
    if header.format != FORMAT || !(1..=FORMAT_VERSION).contains(&header.v) {
        return Err(fail(corrupt(format!(
            "not a {FORMAT} file of version 1 to {FORMAT_VERSION}"
        ))));
    }
    check_header_names(&header, name).map_err(|reason| fail(corrupt(reason)))?;
    let seen = Some(header.version);
    let with_seen = |error: PersistError| Unreadable {
        error,
        version_seen: seen,
    };
    check_header_sizes(&header, line.len() as u64 + 1, file_bytes, max_layer_cells)
        .map_err(|reason| with_seen(corrupt(reason)))?;
    let mut body = vec![0u8; header.bytes as usize];
    reader.read_exact(&mut body).map_err(|e| {
        with_seen(PersistError::Read {
            path: path.to_owned(),
            reason: e.to_string(),
        })
    })?;
    if crc32fast::hash(&body) != header.crc32 {
        return Err(with_seen(corrupt("cell bytes fail their CRC-32".into())));
    }
    let cells = Cells::from_le_bytes(header.dtype, &body)
        .ok_or_else(|| with_seen(corrupt("cell bytes are not whole cells".into())))?;
    Ok(Snapshot {
        layer: Layer {
            name: header.name,
            version: header.version,
            meta: header.meta,
            derived_from: header.derived_from,
            cells,
        },
        derivation: header.derivation,
        file_bytes,
    })
}

/// A FIFO or a device would block or never end; a file larger than any layer is
/// refused before a byte of it is read (a sparse 2 GiB file costs nothing).
fn check_regular_and_small(
    path: &Path,
    file: &File,
    file_bytes: u64,
    max_layer_cells: u64,
) -> Result<(), PersistError> {
    let regular = file.metadata().map(|m| m.is_file()).unwrap_or(false);
    if !regular {
        return Err(PersistError::Corrupt {
            path: path.to_owned(),
            reason: "not a regular file".into(),
        });
    }
    let max = max_file_bytes(max_layer_cells);
    if file_bytes > max {
        return Err(PersistError::Corrupt {
            path: path.to_owned(),
            reason: format!(
                "{file_bytes} bytes, over the largest layer file of {max} bytes (limit max_layer_cells = {max_layer_cells} cells of at most 4 bytes, and a header of at most {MAX_HEADER_BYTES} bytes); it was not read"
            ),
        });
    }
    Ok(())
}

/// The header must name this very layer, with a name that can be a key segment, and
/// claim the derivation this layer has (none, or its one source).
fn check_header_names(header: &Header, name: &str) -> Result<(), String> {
    if keys::check_name("layer name", &header.name).is_err() {
        return Err("its header names no valid layer".into());
    }
    if header.name != name {
        return Err(format!("its header names another layer, not '{name}'"));
    }
    let source = crate::derived::derived_source(name);
    if header.derived_from.as_deref() != source {
        return Err(match source {
            Some(source) => format!("its header does not say it is derived from '{source}'"),
            None => "its header says it is derived, but this layer is not".into(),
        });
    }
    if source.is_some() != header.derivation.is_some() && header.v >= 2 {
        return Err("its header's derivation does not fit the layer".into());
    }
    Ok(())
}

fn check_header_sizes(
    header: &Header,
    header_bytes: u64,
    file_bytes: u64,
    max_layer_cells: u64,
) -> Result<(), String> {
    let meta = &header.meta;
    if !(meta.resolution.is_finite() && meta.resolution > 0.0) {
        return Err("its header's resolution is not a positive number".into());
    }
    let cells = meta.cell_count();
    if cells > max_layer_cells {
        return Err(format!(
            "its header claims {}x{} = {cells} cells, over the limit max_layer_cells = {max_layer_cells}",
            meta.width, meta.height
        ));
    }
    let expected = cells * header.dtype.size() as u64;
    if header.bytes != expected {
        return Err(format!(
            "its header claims {} cell bytes for {cells} {} cells ({expected} bytes)",
            header.bytes,
            header.dtype.as_str()
        ));
    }
    let body = file_bytes.saturating_sub(header_bytes);
    if body < expected {
        return Err(format!("truncated: {body} of {expected} cell bytes"));
    }
    if body > expected {
        return Err(format!(
            "{} bytes after the {expected} cell bytes",
            body - expected
        ));
    }
    Ok(())
}

/// A JSON error as a position and a kind, without the text it found.
pub fn describe_json_error(e: &serde_json::Error) -> String {
    let kind = match e.classify() {
        serde_json::error::Category::Io => "unreadable",
        serde_json::error::Category::Syntax => "not JSON",
        serde_json::error::Category::Data => "unexpected fields or values",
        serde_json::error::Category::Eof => "cut short",
    };
    format!("{kind} at line {}, column {}", e.line(), e.column())
}
