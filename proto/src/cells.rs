//! Grid cells on the wire.
//!
//! Cells are row-major, row 0 at the grid origin (the bottom of a map image, as in ROS
//! `nav_msgs/OccupancyGrid`). They travel as `{"dtype": "i8" | "u8" | "f32", "base64": "..."}`:
//! base64 of the cells' little-endian bytes. That keeps a 1.7-million-cell layer at
//! 2.3 MB of JSON that encodes and decodes in a few milliseconds.

use base64::engine::general_purpose::STANDARD;
use base64::Engine as _;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The cells of one layer.
///
/// - `I8`: occupancy as in ROS: -1 unknown, 0 free ... 100 occupied.
/// - `U8`: scores 0..=100 (the information map).
/// - `F32`: continuous values (heuristic averages, change rates, probabilities, PEB in metres).
#[derive(Debug, Clone, PartialEq)]
pub enum Cells {
    I8(Vec<i8>),
    U8(Vec<u8>),
    F32(Vec<f32>),
}

/// The element type of a layer, as named on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Dtype {
    I8,
    U8,
    F32,
}

impl Dtype {
    pub fn as_str(self) -> &'static str {
        match self {
            Dtype::I8 => "i8",
            Dtype::U8 => "u8",
            Dtype::F32 => "f32",
        }
    }

    /// Bytes per cell.
    pub fn size(self) -> usize {
        match self {
            Dtype::I8 | Dtype::U8 => 1,
            Dtype::F32 => 4,
        }
    }
}

impl Cells {
    pub fn len(&self) -> usize {
        match self {
            Cells::I8(v) => v.len(),
            Cells::U8(v) => v.len(),
            Cells::F32(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn dtype(&self) -> Dtype {
        match self {
            Cells::I8(_) => Dtype::I8,
            Cells::U8(_) => Dtype::U8,
            Cells::F32(_) => Dtype::F32,
        }
    }

    /// The cells' little-endian bytes.
    pub fn to_le_bytes(&self) -> Vec<u8> {
        match self {
            Cells::I8(v) => v.iter().map(|&c| c as u8).collect(),
            Cells::U8(v) => v.clone(),
            Cells::F32(v) => v.iter().flat_map(|c| c.to_le_bytes()).collect(),
        }
    }

    /// Cells from little-endian bytes; `None` when the length is not a whole number of cells.
    pub fn from_le_bytes(dtype: Dtype, bytes: &[u8]) -> Option<Cells> {
        match dtype {
            Dtype::I8 => Some(Cells::I8(bytes.iter().map(|&b| b as i8).collect())),
            Dtype::U8 => Some(Cells::U8(bytes.to_vec())),
            Dtype::F32 => {
                if !bytes.len().is_multiple_of(4) {
                    return None;
                }
                Some(Cells::F32(
                    bytes
                        .chunks_exact(4)
                        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                        .collect(),
                ))
            }
        }
    }

    /// The value of cell `index` as `f64`, or `None` outside the grid.
    pub fn get_f64(&self, index: usize) -> Option<f64> {
        match self {
            Cells::I8(v) => v.get(index).map(|&c| f64::from(c)),
            Cells::U8(v) => v.get(index).map(|&c| f64::from(c)),
            Cells::F32(v) => v.get(index).map(|&c| f64::from(c)),
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CellsWire {
    dtype: Dtype,
    base64: String,
}

impl Serialize for Cells {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        CellsWire {
            dtype: self.dtype(),
            base64: STANDARD.encode(self.to_le_bytes()),
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Cells {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let wire = CellsWire::deserialize(deserializer)?;
        let bytes = STANDARD
            .decode(wire.base64.as_bytes())
            .map_err(|e| D::Error::custom(format!("cells are not valid base64: {e}")))?;
        Cells::from_le_bytes(wire.dtype, &bytes).ok_or_else(|| {
            D::Error::custom(format!(
                "{} bytes of cells are not a whole number of {} cells",
                bytes.len(),
                wire.dtype.as_str()
            ))
        })
    }
}
