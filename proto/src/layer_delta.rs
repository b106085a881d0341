//! A small change to a layer, on the wire: the cells a change wrote, with the version
//! they apply to and the version they make.
//!
//! The map server publishes a `set_cells` change (and what its derived layer gains from
//! it) as a [`LayerDelta`] on `<root>/map/delta/<name>` instead of the whole layer on
//! `<root>/map/layer/<name>`: a one-cell change to a 4096 × 4096 f32 layer is then a
//! message of about 200 bytes, not of 90 MB. A follower holding the layer at exactly
//! `base_version` applies it ([`LayerDelta::apply`]); any other follower (one that
//! missed a delta, or holds nothing yet) gets the whole layer with a `get` on
//! `<root>/map/layer/<name>`.

use base64::engine::general_purpose::STANDARD;
use base64::Engine as _;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::cells::Cells;
use crate::codec::Message;
use crate::map::Layer;

/// The most cells one delta carries; the map server publishes a larger change as the
/// whole layer. The parse refuses more before it allocates them.
pub const MAX_DELTA_CELLS: usize = 1_048_576;

/// The largest encoded delta, bytes: [`MAX_DELTA_CELLS`] positions (8 bytes each) and
/// f32 values (4 each) in base64 (16 characters a cell), with room for the envelope.
pub const MAX_DELTA_BYTES: usize = MAX_DELTA_CELLS * 16 + 64 * 1024;

/// The cells a change wrote into layer `name`, which takes it from `base_version` to
/// `version`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerDelta {
    pub name: String,
    /// The version the change applies to.
    pub base_version: u64,
    /// The layer's version after it.
    pub version: u64,
    /// The cells written, in order (a later write to the same cell wins).
    pub positions: CellPositions,
    /// Their new values, one per position, in the layer's element type.
    pub values: Cells,
}

impl Message for LayerDelta {
    const KIND: &'static str = "layer_delta";
}

/// Cell positions (column `x`, row `y`, row 0 at the origin), on the wire as base64 of
/// `x` and `y` as u32 little-endian, pair after pair: 8 bytes a cell.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CellPositions(pub Vec<(u32, u32)>);

impl Serialize for CellPositions {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let bytes: Vec<u8> = self
            .0
            .iter()
            .flat_map(|&(x, y)| x.to_le_bytes().into_iter().chain(y.to_le_bytes()))
            .collect();
        serializer.serialize_str(&STANDARD.encode(bytes))
    }
}

impl<'de> Deserialize<'de> for CellPositions {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = <std::borrow::Cow<'de, str>>::deserialize(deserializer)?;
        // Checked before decoding: base64 is 4 characters for 3 bytes.
        let max_chars = (MAX_DELTA_CELLS * 8).div_ceil(3) * 4;
        if text.len() > max_chars {
            return Err(D::Error::custom(format!(
                "more than {MAX_DELTA_CELLS} positions (max_delta_cells); a larger change travels as the whole layer"
            )));
        }
        let bytes = STANDARD
            .decode(text.as_bytes())
            .map_err(|e| D::Error::custom(format!("positions are not valid base64: {e}")))?;
        if !bytes.len().is_multiple_of(8) {
            return Err(D::Error::custom(format!(
                "{} bytes of positions are not a whole number of (x, y) u32 pairs",
                bytes.len()
            )));
        }
        let word = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        Ok(CellPositions(
            bytes
                .chunks_exact(8)
                .map(|p| (word(&p[..4]), word(&p[4..])))
                .collect(),
        ))
    }
}

/// Why a delta does not apply to the layer a follower holds. Nothing was written.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DeltaError {
    #[error("the delta is for layer '{delta}', not '{layer}'")]
    OtherLayer { delta: String, layer: String },
    #[error("the delta applies to version {base}, but the layer held is version {held}; get the whole layer")]
    Gap { base: u64, held: u64 },
    #[error("the delta does not make a newer version ({base} to {version})")]
    NotNewer { base: u64, version: u64 },
    #[error("the delta holds {values} values of type {found} for {positions} positions of a layer of {expected} cells")]
    Shape {
        positions: usize,
        values: usize,
        found: &'static str,
        expected: &'static str,
    },
    #[error("the delta writes cell ({x}, {y}), outside the {width}x{height} layer")]
    Outside {
        x: u32,
        y: u32,
        width: u32,
        height: u32,
    },
}

impl LayerDelta {
    /// Writes the delta into `layer`, which must be the delta's layer at exactly
    /// `base_version`, and gives it `version`. Every check comes first: on an error the
    /// layer is as it was.
    pub fn apply(&self, layer: &mut Layer) -> Result<(), DeltaError> {
        if self.name != layer.name {
            return Err(DeltaError::OtherLayer {
                delta: crate::excerpt(&self.name).to_string(),
                layer: layer.name.clone(),
            });
        }
        if self.version <= self.base_version {
            return Err(DeltaError::NotNewer {
                base: self.base_version,
                version: self.version,
            });
        }
        if layer.version != self.base_version {
            return Err(DeltaError::Gap {
                base: self.base_version,
                held: layer.version,
            });
        }
        let expected = layer.cells.dtype();
        if self.values.dtype() != expected || self.values.len() != self.positions.0.len() {
            return Err(DeltaError::Shape {
                positions: self.positions.0.len(),
                values: self.values.len(),
                found: self.values.dtype().as_str(),
                expected: expected.as_str(),
            });
        }
        let (width, height) = (layer.meta.width, layer.meta.height);
        if let Some(&(x, y)) = self
            .positions
            .0
            .iter()
            .find(|&&(x, y)| x >= width || y >= height)
        {
            return Err(DeltaError::Outside {
                x,
                y,
                width,
                height,
            });
        }
        let index = |&(x, y): &(u32, u32)| y as usize * width as usize + x as usize;
        let positions = self.positions.0.iter().map(index);
        match (&mut layer.cells, &self.values) {
            (Cells::I8(cells), Cells::I8(values)) => write(cells, positions, values),
            (Cells::U8(cells), Cells::U8(values)) => write(cells, positions, values),
            (Cells::F32(cells), Cells::F32(values)) => write(cells, positions, values),
            // The element types were compared above.
            _ => {}
        }
        layer.version = self.version;
        Ok(())
    }
}

fn write<T: Copy>(cells: &mut [T], positions: impl Iterator<Item = usize>, values: &[T]) {
    for (i, &value) in positions.zip(values) {
        if let Some(cell) = cells.get_mut(i) {
            *cell = value;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{GridMeta, Origin};

    fn layer(version: u64) -> Layer {
        Layer {
            name: "peb".into(),
            version,
            meta: GridMeta {
                width: 3,
                height: 2,
                resolution: 1.0,
                origin: Origin::default(),
            },
            derived_from: None,
            cells: Cells::F32(vec![0.0; 6]),
        }
    }

    fn delta(base_version: u64, positions: Vec<(u32, u32)>, values: Vec<f32>) -> LayerDelta {
        LayerDelta {
            name: "peb".into(),
            base_version,
            version: base_version + 1,
            positions: CellPositions(positions),
            values: Cells::F32(values),
        }
    }

    #[test]
    fn a_delta_round_trips_and_applies_at_its_base() {
        let d = delta(4, vec![(2, 1), (0, 0), (2, 1)], vec![1.0, 2.0, 3.0]);
        let back: LayerDelta = crate::decode(&crate::encode(&d)).expect("decode");
        assert_eq!(back, d);
        let mut l = layer(4);
        back.apply(&mut l).expect("applies");
        assert_eq!(l.version, 5);
        assert_eq!(l.cells, Cells::F32(vec![2.0, 0.0, 0.0, 0.0, 0.0, 3.0]));
    }

    #[test]
    fn a_delta_that_does_not_fit_changes_nothing() {
        let cases = [
            (layer(3), delta(4, vec![(0, 0)], vec![1.0])),
            (layer(4), delta(4, vec![(3, 0)], vec![1.0])),
            (layer(4), delta(4, vec![(0, 0)], vec![])),
            (
                layer(4),
                LayerDelta {
                    values: Cells::U8(vec![1]),
                    ..delta(4, vec![(0, 0)], vec![])
                },
            ),
            (
                layer(4),
                LayerDelta {
                    version: 4,
                    ..delta(4, vec![(0, 0)], vec![1.0])
                },
            ),
            (
                layer(4),
                LayerDelta {
                    name: "other".into(),
                    ..delta(4, vec![(0, 0)], vec![1.0])
                },
            ),
        ];
        for (mut l, d) in cases {
            let before = l.clone();
            assert!(d.apply(&mut l).is_err(), "{d:?}");
            assert_eq!(l, before);
        }
        let gap = delta(4, vec![(0, 0)], vec![1.0]).apply(&mut layer(2));
        assert_eq!(gap, Err(DeltaError::Gap { base: 4, held: 2 }));
    }

    #[test]
    fn the_largest_delta_fits_its_byte_limit() {
        let d = LayerDelta {
            name: "x".repeat(64),
            base_version: u64::MAX - 1,
            version: u64::MAX,
            positions: CellPositions(vec![(u32::MAX, u32::MAX); MAX_DELTA_CELLS]),
            values: Cells::F32(vec![f32::MAX; MAX_DELTA_CELLS]),
        };
        let bytes = crate::encode(&d).len();
        assert!(bytes <= MAX_DELTA_BYTES, "{bytes} > {MAX_DELTA_BYTES}");
    }

    #[test]
    fn too_many_positions_are_refused_before_decoding() {
        let chars = (MAX_DELTA_CELLS * 8).div_ceil(3) * 4 + 4;
        let json = format!(
            r#"{{"v":1,"kind":"layer_delta","body":{{"name":"peb","base_version":1,"version":2,"positions":"{}","values":{{"dtype":"f32","base64":""}}}}}}"#,
            "A".repeat(chars)
        );
        let refused = crate::decode::<LayerDelta>(json.as_bytes()).expect_err("too many");
        assert!(refused.to_string().contains("max_delta_cells"), "{refused}");
    }
}
