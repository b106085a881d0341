//! Cell edits: the checked form of a `set_cells` update, and of what a derived layer
//! gains from it. The store applies them in place and the change log stores them, so a
//! one-cell update costs one cell of memory traffic and disk, not the layer.

use roam_proto::cells::{Cells, Dtype};
use roam_proto::map::{CellWrite, GridMeta, Layer};
use roam_proto::number;

use roam_world::grid::occupancy;

/// Cell positions and their new values, in the order they are applied (a later write to
/// the same cell wins). `values` has the layer's element type and one value per
/// position.
#[derive(Debug, Clone, PartialEq)]
pub struct CellEdits {
    pub positions: Vec<(u32, u32)>,
    pub values: Cells,
}

/// Why a cell write was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EditError {
    #[error("cell ({x}, {y}) is outside layer '{layer}' ({width}x{height}); x is the column 0..{width}, y the row 0..{height}")]
    Outside {
        layer: String,
        x: u32,
        y: u32,
        width: u32,
        height: u32,
    },
    #[error("value {} at ({x}, {y}) is outside {}..={} for layer '{layer}'", number(*.value), number(*.lo), number(*.hi))]
    Value {
        layer: String,
        x: u32,
        y: u32,
        value: f64,
        lo: f64,
        hi: f64,
    },
    #[error("the edits hold {found} values for a layer of {expected} values")]
    Dtype {
        expected: &'static str,
        found: &'static str,
    },
    #[error("the edits hold {positions} positions but {values} values")]
    Count { positions: usize, values: usize },
}

/// The values a cell of layer `name` with cells of type `dtype` may take.
pub fn value_range(name: &str, dtype: Dtype) -> (f64, f64) {
    match (name, dtype) {
        (roam_proto::map::OCCUPANCY_LAYER, _) => (f64::from(occupancy::UNKNOWN), 100.0),
        (roam_proto::map::INFORMATION_LAYER, _) => (0.0, 100.0),
        (_, Dtype::I8) => (-128.0, 127.0),
        (_, Dtype::U8) => (0.0, 255.0),
        (_, Dtype::F32) => (f64::from(f32::MIN), f64::from(f32::MAX)),
    }
}

impl EditError {
    /// What is wrong, without the positions and values (for edits read from a file,
    /// whose content a message never quotes).
    pub fn short(&self) -> &'static str {
        match self {
            EditError::Outside { .. } => "a cell outside the layer",
            EditError::Value { .. } => "a value out of the layer's range",
            EditError::Dtype { .. } => "values of another element type",
            EditError::Count { .. } => "not one value per position",
        }
    }
}

impl CellEdits {
    /// No edit, for a layer of `dtype`.
    pub fn empty(dtype: Dtype) -> Self {
        CellEdits {
            positions: Vec::new(),
            values: match dtype {
                Dtype::I8 => Cells::I8(Vec::new()),
                Dtype::U8 => Cells::U8(Vec::new()),
                Dtype::F32 => Cells::F32(Vec::new()),
            },
        }
    }

    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Checks `writes` against `layer` (positions inside it, values in its range once
    /// rounded to its type) and turns them into edits.
    pub fn from_writes(layer: &Layer, writes: &[CellWrite]) -> Result<Self, EditError> {
        let dtype = layer.cells.dtype();
        let (lo, hi) = value_range(&layer.name, dtype);
        let mut edits = CellEdits::empty(dtype);
        edits.positions.reserve(writes.len());
        for write in writes {
            check_inside(&layer.name, &layer.meta, write.x, write.y)?;
            let value = if dtype == Dtype::F32 {
                write.value
            } else {
                write.value.round()
            };
            if !(value.is_finite() && (lo..=hi).contains(&value)) {
                return Err(EditError::Value {
                    layer: layer.name.clone(),
                    x: write.x,
                    y: write.y,
                    value: write.value,
                    lo,
                    hi,
                });
            }
            edits.positions.push((write.x, write.y));
            match &mut edits.values {
                Cells::I8(v) => v.push(value as i8),
                Cells::U8(v) => v.push(value as u8),
                Cells::F32(v) => v.push(value as f32),
            }
        }
        Ok(edits)
    }

    /// Checks edits read back from disk against the layer they apply to: the same
    /// element type, one value per position, every position inside, every value in
    /// range (a NaN is never a value).
    pub fn check(&self, layer: &Layer) -> Result<(), EditError> {
        let expected = layer.cells.dtype();
        if self.values.dtype() != expected {
            return Err(EditError::Dtype {
                expected: expected.as_str(),
                found: self.values.dtype().as_str(),
            });
        }
        if self.values.len() != self.positions.len() {
            return Err(EditError::Count {
                positions: self.positions.len(),
                values: self.values.len(),
            });
        }
        let (lo, hi) = value_range(&layer.name, expected);
        for (i, &(x, y)) in self.positions.iter().enumerate() {
            check_inside(&layer.name, &layer.meta, x, y)?;
            let value = self.values.get_f64(i).unwrap_or(f64::NAN);
            if !(lo..=hi).contains(&value) && !value.is_infinite() {
                return Err(EditError::Value {
                    layer: layer.name.clone(),
                    x,
                    y,
                    value,
                    lo,
                    hi,
                });
            }
        }
        Ok(())
    }

    /// Writes the edits into `cells` (a grid of `meta`), in order. Positions and types
    /// were checked when the edits were made.
    pub fn apply(&self, meta: &GridMeta, cells: &mut Cells) {
        let width = meta.width as usize;
        let index = |&(x, y): &(u32, u32)| y as usize * width + x as usize;
        match (cells, &self.values) {
            (Cells::I8(c), Cells::I8(v)) => {
                for (p, &value) in self.positions.iter().zip(v) {
                    if let Some(cell) = c.get_mut(index(p)) {
                        *cell = value;
                    }
                }
            }
            (Cells::U8(c), Cells::U8(v)) => {
                for (p, &value) in self.positions.iter().zip(v) {
                    if let Some(cell) = c.get_mut(index(p)) {
                        *cell = value;
                    }
                }
            }
            (Cells::F32(c), Cells::F32(v)) => {
                for (p, &value) in self.positions.iter().zip(v) {
                    if let Some(cell) = c.get_mut(index(p)) {
                        *cell = value;
                    }
                }
            }
            // Checked by `from_writes` and `check`; a mismatch would be a bug, and
            // writing nothing keeps the layer as it was.
            _ => tracing::error!("cell edits of another element type were not applied"),
        }
    }

    /// The smallest rectangle `(x0, y0, x1, y1)` (inclusive) holding every position.
    pub fn bounds(&self) -> Option<(u32, u32, u32, u32)> {
        let mut it = self.positions.iter();
        let &(x, y) = it.next()?;
        Some(it.fold((x, y, x, y), |(x0, y0, x1, y1), &(x, y)| {
            (x0.min(x), y0.min(y), x1.max(x), y1.max(y))
        }))
    }
}

fn check_inside(name: &str, meta: &GridMeta, x: u32, y: u32) -> Result<(), EditError> {
    if x >= meta.width || y >= meta.height {
        return Err(EditError::Outside {
            layer: name.to_owned(),
            x,
            y,
            width: meta.width,
            height: meta.height,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    fn layer(name: &str, cells: Cells) -> Layer {
        Layer {
            name: name.into(),
            version: 1,
            meta: GridMeta {
                width: 4,
                height: 2,
                resolution: 1.0,
                origin: Origin::default(),
            },
            derived_from: None,
            cells,
        }
    }

    #[test]
    fn writes_become_typed_edits_applied_in_order() {
        let mut l = layer("occupancy", Cells::I8(vec![0; 8]));
        let writes = [
            CellWrite {
                x: 1,
                y: 1,
                value: 99.6,
            },
            CellWrite {
                x: 1,
                y: 1,
                value: 100.0,
            },
            CellWrite {
                x: 3,
                y: 0,
                value: -1.0,
            },
        ];
        let edits = CellEdits::from_writes(&l, &writes).expect("valid");
        assert_eq!(edits.bounds(), Some((1, 0, 3, 1)));
        edits.apply(&l.meta.clone(), &mut l.cells);
        assert_eq!(l.cells, Cells::I8(vec![0, 0, 0, -1, 0, 100, 0, 0]));
        assert!(edits.check(&l).is_ok());
    }

    #[test]
    fn out_of_range_and_outside_writes_are_refused() {
        let l = layer("occupancy", Cells::I8(vec![0; 8]));
        let outside = CellEdits::from_writes(
            &l,
            &[CellWrite {
                x: 4,
                y: 0,
                value: 0.0,
            }],
        );
        assert!(matches!(outside, Err(EditError::Outside { .. })));
        let big = CellEdits::from_writes(
            &l,
            &[CellWrite {
                x: 0,
                y: 0,
                value: 101.0,
            }],
        );
        assert!(matches!(big, Err(EditError::Value { .. })));
        let f = layer("peb", Cells::F32(vec![0.0; 8]));
        let nan = CellEdits {
            positions: vec![(0, 0)],
            values: Cells::F32(vec![f32::NAN]),
        };
        assert!(nan.check(&f).is_err());
        let inf = CellEdits {
            positions: vec![(0, 0)],
            values: Cells::F32(vec![f32::INFINITY]),
        };
        assert!(inf.check(&f).is_ok(), "an unbounded PEB is a value");
        assert!(matches!(inf.check(&l), Err(EditError::Dtype { .. })));
    }
}
