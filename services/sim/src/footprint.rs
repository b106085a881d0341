//! How many cells an obstacle covers: the sim's walls, blocks, walkers and the
//! semi-static objects all place theirs with it.

use roam_proto::map::GridMeta;
use serde::Serialize;

use crate::raster::CellXy;

/// How many cells an obstacle covers, centred on the cell its position falls in; for an
/// even size the extra column (row) is on the +x (+y) side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Footprint {
    pub width_cells: u32,
    pub height_cells: u32,
}

impl Footprint {
    /// Metres rounded to whole cells, at least one.
    pub fn from_metres(meta: &GridMeta, [w, h]: [f64; 2]) -> Footprint {
        let cells = |m: f64| ((m / meta.resolution).round() as u32).max(1);
        Footprint {
            width_cells: cells(w),
            height_cells: cells(h),
        }
    }

    /// The cells covered when centred on `centre`, possibly partly off the map.
    pub fn cells(&self, centre: CellXy) -> impl Iterator<Item = CellXy> {
        let (w, h) = (i64::from(self.width_cells), i64::from(self.height_cells));
        let (x0, y0) = (centre.0 - (w - 1) / 2, centre.1 - (h - 1) / 2);
        (y0..y0 + h).flat_map(move |y| (x0..x0 + w).map(move |x| (x, y)))
    }
}
