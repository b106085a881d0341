//! The change log of one layer, `<name>.log`: the `set_cells` changes made since its
//! snapshot, so that a small change costs a small append instead of a rewrite.
//!
//! A header line `{"format": "roam-layer-log", "v": 1, "name": "<name>"}`, then records:
//!
//! | bytes | what |
//! |---|---|
//! | 4 | payload length, u32 LE |
//! | 4 | CRC-32 of the payload, u32 LE |
//! | 8 | the layer version this record produces, u64 LE |
//! | 8 | for a derived layer, the source version it is computed from (else 0), u64 LE |
//! | 1 | element type: 0 i8, 1 u8, 2 f32 |
//! | 4 | cell count n, u32 LE |
//! | 8 n | positions: x u32 LE, y u32 LE |
//! | n × size | values, little-endian, in the element type |
//!
//! A record is appended with one `write` and fsynced before the change is acknowledged.
//! Reading stops at the first record that is incomplete or fails its CRC: when it is the
//! last thing in the file it is a torn append (a crash during the write, never
//! acknowledged) and is dropped; anything after a bad record is corruption, reported.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;

use roam_proto::cells::{Cells, Dtype};
use serde::{Deserialize, Serialize};

use super::error::PersistError;
use super::snapshot::describe_json_error;
use crate::edits::CellEdits;

const FORMAT: &str = "roam-layer-log";
const FORMAT_VERSION: u32 = 1;
const MAX_HEADER_BYTES: u64 = 4096;
/// Length and CRC in front of each payload.
const FRAME_BYTES: u64 = 8;
/// Version, source version, element type and count.
const FIXED_PAYLOAD_BYTES: u64 = 8 + 8 + 1 + 4;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    format: String,
    v: u32,
    name: String,
}

/// One change: the version it produces and the cells it writes.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub version: u64,
    /// For a derived layer, the source version it is then computed from; 0 otherwise.
    pub source_version: u64,
    pub edits: CellEdits,
}

/// How a log ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Tail {
    /// After its last complete record.
    Clean,
    /// In an incomplete last record of `bytes` bytes: a torn append.
    Torn { bytes: u64 },
    /// At a bad record with more bytes after it.
    Corrupt { offset: u64, reason: String },
}

/// What reading a log found.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    pub records: Vec<Record>,
    /// The length of the header and the good records: where the next append goes.
    pub good_bytes: u64,
    pub tail: Tail,
}

/// The bytes a record of `count` cells of `dtype` takes in the log.
pub fn record_bytes(count: usize, dtype: Dtype) -> u64 {
    FRAME_BYTES + FIXED_PAYLOAD_BYTES + count as u64 * (8 + dtype.size() as u64)
}

fn dtype_code(dtype: Dtype) -> u8 {
    match dtype {
        Dtype::I8 => 0,
        Dtype::U8 => 1,
        Dtype::F32 => 2,
    }
}

/// The framed bytes of the record that makes `version` with `edits`.
pub fn encode(version: u64, source_version: u64, edits: &CellEdits) -> Vec<u8> {
    let dtype = edits.values.dtype();
    let mut payload = Vec::with_capacity(record_bytes(edits.len(), dtype) as usize);
    payload.extend_from_slice(&version.to_le_bytes());
    payload.extend_from_slice(&source_version.to_le_bytes());
    payload.push(dtype_code(dtype));
    payload.extend_from_slice(&(edits.len() as u32).to_le_bytes());
    for &(x, y) in &edits.positions {
        payload.extend_from_slice(&x.to_le_bytes());
        payload.extend_from_slice(&y.to_le_bytes());
    }
    payload.extend_from_slice(&edits.values.to_le_bytes());
    let mut framed = Vec::with_capacity(payload.len() + FRAME_BYTES as usize);
    framed.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    framed.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    framed.extend_from_slice(&payload);
    framed
}

fn decode_payload(payload: &[u8]) -> Result<Record, String> {
    let take = |at: usize, n: usize| payload.get(at..at + n).ok_or("cut short");
    let u64_at = |at: usize| -> Result<u64, &'static str> {
        let b = take(at, 8)?;
        Ok(u64::from_le_bytes([
            b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7],
        ]))
    };
    let u32_at = |at: usize| -> Result<u32, &'static str> {
        let b = take(at, 4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let version = u64_at(0)?;
    let source_version = u64_at(8)?;
    let dtype = match take(16, 1)?[0] {
        0 => Dtype::I8,
        1 => Dtype::U8,
        2 => Dtype::F32,
        _ => return Err("an unknown element type".into()),
    };
    let count = u32_at(17)? as usize;
    let expected = record_bytes(count, dtype) - FRAME_BYTES;
    if payload.len() as u64 != expected {
        return Err(format!(
            "{} payload bytes for {count} cells ({expected} expected)",
            payload.len()
        ));
    }
    let start = FIXED_PAYLOAD_BYTES as usize;
    let positions = (0..count)
        .map(|i| Ok((u32_at(start + 8 * i)?, u32_at(start + 8 * i + 4)?)))
        .collect::<Result<Vec<_>, &str>>()?;
    let values = Cells::from_le_bytes(dtype, &payload[start + 8 * count..])
        .ok_or("values that are not whole cells")?;
    Ok(Record {
        version,
        source_version,
        edits: CellEdits { positions, values },
    })
}

/// Appends one framed record to the log of `name` at `path` (writing the header first
/// when the file is new) and fsyncs it. Returns the log's length before the append,
/// where a rollback truncates it to.
pub fn append(path: &Path, name: &str, framed: &[u8]) -> Result<u64, PersistError> {
    let write_err = |e: std::io::Error| PersistError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    };
    let mut file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(write_err)?;
    let mut before = file.metadata().map_err(write_err)?.len();
    if before == 0 {
        let header = Header {
            format: FORMAT.into(),
            v: FORMAT_VERSION,
            name: name.to_owned(),
        };
        let mut line = serde_json::to_vec(&header).map_err(|e| PersistError::Write {
            path: path.to_owned(),
            reason: e.to_string(),
        })?;
        line.push(b'\n');
        file.write_all(&line).map_err(write_err)?;
        before = line.len() as u64;
    }
    file.write_all(framed).map_err(write_err)?;
    // sync_data also makes the new length durable, which is what a reader needs.
    file.sync_data().map_err(write_err)?;
    Ok(before)
}

/// Cuts the log back to `len` bytes (a record whose change was not applied).
pub fn truncate(path: &Path, len: u64) -> Result<(), PersistError> {
    let write_err = |e: std::io::Error| PersistError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    };
    let file = OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(write_err)?;
    file.set_len(len).map_err(write_err)?;
    file.sync_data().map_err(write_err)
}

/// Reads the log of `name` at `path`. A log over `max_bytes` or with a header naming
/// another layer is an error (nothing of it is used); bad records end the scan.
pub fn scan(
    path: &Path,
    name: &str,
    max_record_bytes: u64,
    max_bytes: u64,
) -> Result<Scan, PersistError> {
    let read_err = |e: std::io::Error| PersistError::Read {
        path: path.to_owned(),
        reason: e.to_string(),
    };
    let corrupt = |reason: String| PersistError::Corrupt {
        path: path.to_owned(),
        reason,
    };
    let file = File::open(path).map_err(read_err)?;
    let meta = file.metadata().map_err(read_err)?;
    if !meta.is_file() {
        return Err(corrupt("not a regular file".into()));
    }
    let len = meta.len();
    if len > max_bytes {
        return Err(corrupt(format!(
            "{len} bytes, over the largest change log of {max_bytes} bytes (four times the largest layer file, from the limit max_layer_cells); it was not read"
        )));
    }
    let mut reader = BufReader::new(file);
    let mut line = Vec::new();
    (&mut reader)
        .take(MAX_HEADER_BYTES)
        .read_until(b'\n', &mut line)
        .map_err(read_err)?;
    if line.pop() != Some(b'\n') {
        if line.is_empty() || line.len() as u64 == len {
            // A crash while the header of a new log was written: no record yet.
            return Ok(Scan {
                records: Vec::new(),
                good_bytes: 0,
                tail: if len == 0 {
                    Tail::Clean
                } else {
                    Tail::Torn { bytes: len }
                },
            });
        }
        return Err(corrupt(format!(
            "no header line in its first {MAX_HEADER_BYTES} bytes"
        )));
    }
    let header: Header = serde_json::from_slice(&line)
        .map_err(|e| corrupt(format!("bad header: {}", describe_json_error(&e))))?;
    if header.format != FORMAT || header.v != FORMAT_VERSION {
        return Err(corrupt(format!("not a {FORMAT} v{FORMAT_VERSION} file")));
    }
    if header.name != name {
        return Err(corrupt(format!(
            "its header names another layer, not '{name}'"
        )));
    }
    let mut offset = line.len() as u64 + 1;
    let mut records = Vec::new();
    let tail = loop {
        if offset == len {
            break Tail::Clean;
        }
        let rest = len - offset;
        let mut frame = [0u8; FRAME_BYTES as usize];
        if rest < FRAME_BYTES {
            break Tail::Torn { bytes: rest };
        }
        reader.read_exact(&mut frame).map_err(read_err)?;
        let payload_len = u64::from(u32::from_le_bytes([frame[0], frame[1], frame[2], frame[3]]));
        let crc = u32::from_le_bytes([frame[4], frame[5], frame[6], frame[7]]);
        let end = offset + FRAME_BYTES + payload_len;
        if payload_len < FIXED_PAYLOAD_BYTES || payload_len > max_record_bytes {
            break bad_tail(&mut reader, &frame, offset, "a record length out of bounds")?;
        }
        if end > len {
            break Tail::Torn { bytes: rest };
        }
        let mut payload = vec![0u8; payload_len as usize];
        reader.read_exact(&mut payload).map_err(read_err)?;
        if crc32fast::hash(&payload) != crc {
            if end == len {
                break Tail::Torn { bytes: rest };
            }
            break Tail::Corrupt {
                offset,
                reason: format!("the record at byte {offset} fails its CRC-32"),
            };
        }
        match decode_payload(&payload) {
            Ok(record) => records.push(record),
            Err(reason) => {
                break Tail::Corrupt {
                    offset,
                    reason: format!("the record at byte {offset} has {reason}"),
                }
            }
        }
        offset = end;
    };
    Ok(Scan {
        records,
        good_bytes: offset,
        tail,
    })
}

/// A record whose frame cannot be right: a torn append when it and everything after it
/// are zeros (a file extended before its data reached the disk), corruption otherwise.
fn bad_tail(
    reader: &mut impl Read,
    frame: &[u8],
    offset: u64,
    reason: &str,
) -> Result<Tail, PersistError> {
    let mut zeros = frame.iter().all(|&b| b == 0);
    let mut bytes = frame.len() as u64;
    let mut chunk = [0u8; 8192];
    while zeros {
        match reader.read(&mut chunk) {
            Ok(0) | Err(_) => break,
            Ok(n) => {
                zeros = chunk[..n].iter().all(|&b| b == 0);
                bytes += n as u64;
            }
        }
    }
    if zeros {
        return Ok(Tail::Torn { bytes });
    }
    Ok(Tail::Corrupt {
        offset,
        reason: format!("{reason} at byte {offset}"),
    })
}
