//! Line of sight on the grid: which cells within a radius a robot sees, as a laser would.
//!
//! A cell is seen when the segment from the centre of the robot's cell to the centre
//! of that cell crosses no blocking cell before it ([`raster::cells_between`], a
//! supercover walk: diagonal walls are opaque). The blocking cell that stops a ray is
//! itself seen.
//!
//! Walking every ray costs O(r³) cells for a radius of r cells. Instead the segments
//! are laid out once per radius (they are the same wherever the robot stands): for each
//! cell near the robot, the list of cells it hides. An observation then marks what the
//! blocking cells in view hide, and only the blocking cells with a free 4-neighbour need
//! to: a segment reaching a blocking cell whose 4-neighbours all block has passed one
//! of those neighbours just before (the walk is 4-connected), so it was already hidden.
//! The result is exactly the per-ray definition, in O(r²) plus the shadows of the
//! obstacle boundaries in view.

use crate::raster::{self, CellXy};

/// The precomputed rays for one radius.
#[derive(Debug, Clone)]
pub struct LosTable {
    radius_cells: i64,
    /// Offsets (from the robot's cell) of the cells within the radius.
    disk: Vec<CellXy>,
    /// For each offset in the (2R+1)² square around the robot (row-major), the range in
    /// `hidden` of the disk cells it hides when it blocks (compressed rows).
    start: Vec<u32>,
    hidden: Vec<u32>,
}

pub use roam_world::observation::{Observation, FREE, OCCUPIED, UNSEEN};

impl LosTable {
    /// The rays for cells whose centres are within `radius_cells` of the robot's cell
    /// centre.
    pub fn new(radius_cells: f64) -> LosTable {
        let r = radius_cells.max(0.0).floor() as i64;
        let r2 = radius_cells * radius_cells + 1e-9;
        let side = 2 * r + 1;
        let mut disk: Vec<CellXy> = (-r..=r)
            .flat_map(|dy| (-r..=r).map(move |dx| (dx, dy)))
            .filter(|&(dx, dy)| (dx * dx + dy * dy) as f64 <= r2)
            .collect();
        disk.sort_by_key(|&(dx, dy)| (dx * dx + dy * dy, dy, dx));
        let square = |(dx, dy): CellXy| ((dy + r) * side + dx + r) as usize;
        // (occluder, hidden) pairs, then grouped by occluder.
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (k, &(dx, dy)) in disk.iter().enumerate() {
            for c in raster::cells_between(dx, dy) {
                pairs.push((square(c) as u32, k as u32));
            }
        }
        pairs.sort_unstable();
        let mut start = vec![0u32; (side * side) as usize + 1];
        for &(s, _) in &pairs {
            start[s as usize + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        LosTable {
            radius_cells: r,
            disk,
            start,
            hidden: pairs.into_iter().map(|(_, k)| k).collect(),
        }
    }

    /// The radius in whole cells.
    pub fn radius_cells(&self) -> i64 {
        self.radius_cells
    }

    /// What a robot in cell `centre` sees on a `width` × `height` map where `blocked`
    /// tells which cells block sight (it is asked only about cells on the map).
    pub fn observe(
        &self,
        centre: CellXy,
        width: u32,
        height: u32,
        blocked: impl Fn(CellXy) -> bool,
    ) -> Observation {
        let r = self.radius_cells;
        let side = 2 * r + 1;
        let (w, h) = (i64::from(width), i64::from(height));
        let on_map = |(x, y): CellXy| x >= 0 && y >= 0 && x < w && y < h;
        let mut visible = vec![true; self.disk.len()];
        for sy in 0..side {
            for sx in 0..side {
                let s = (sy * side + sx) as usize;
                let (a, b) = (self.start[s] as usize, self.start[s + 1] as usize);
                if a == b {
                    continue;
                }
                let cell = (centre.0 + sx - r, centre.1 + sy - r);
                if !on_map(cell) || !blocked(cell) {
                    continue;
                }
                let boundary = [(1, 0), (0, 1), (-1, 0), (0, -1)].iter().any(|(dx, dy)| {
                    let n = (cell.0 + dx, cell.1 + dy);
                    on_map(n) && !blocked(n)
                });
                if boundary {
                    for &k in &self.hidden[a..b] {
                        visible[k as usize] = false;
                    }
                }
            }
        }
        let x0 = (centre.0 - r).clamp(0, w.max(1) - 1);
        let y0 = (centre.1 - r).clamp(0, h.max(1) - 1);
        let x1 = (centre.0 + r).clamp(0, w.max(1) - 1);
        let y1 = (centre.1 + r).clamp(0, h.max(1) - 1);
        let (ww, wh) = ((x1 - x0 + 1).max(0), (y1 - y0 + 1).max(0));
        let mut cells = vec![UNSEEN; (ww * wh) as usize];
        for (k, &(dx, dy)) in self.disk.iter().enumerate() {
            let cell = (centre.0 + dx, centre.1 + dy);
            if !visible[k] || !on_map(cell) {
                continue;
            }
            let i = ((cell.1 - y0) * ww + (cell.0 - x0)) as usize;
            cells[i] = if blocked(cell) { OCCUPIED } else { FREE };
        }
        Observation {
            x0: x0 as u32,
            y0: y0 as u32,
            width: ww as u32,
            height: wh as u32,
            cells,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition, ray by ray, for checking the table against.
    fn seen_by_rays(
        centre: CellXy,
        r: f64,
        on: impl Fn(CellXy) -> bool,
        blocked: impl Fn(CellXy) -> bool,
    ) -> Vec<(CellXy, bool)> {
        let ri = r.floor() as i64;
        let mut out = Vec::new();
        for dy in -ri..=ri {
            for dx in -ri..=ri {
                if (dx * dx + dy * dy) as f64 > r * r + 1e-9 {
                    continue;
                }
                let c = (centre.0 + dx, centre.1 + dy);
                if !on(c) {
                    continue;
                }
                let clear = raster::cells_between(dx, dy)
                    .into_iter()
                    .all(|(ox, oy)| !blocked((centre.0 + ox, centre.1 + oy)));
                out.push((c, clear));
            }
        }
        out
    }

    #[test]
    fn the_table_agrees_with_walking_every_ray() {
        // A cluttered 40 x 40 map: a filled room, a diagonal wall, scattered cells.
        let blocked = |(x, y): CellXy| {
            (10..=18).contains(&x) && (5..=12).contains(&y)
                || (x - y == 7 && x > 20)
                || (x * 7 + y * 13) % 11 == 0 && x % 3 == 0
        };
        let on = |(x, y): CellXy| (0..40).contains(&x) && (0..40).contains(&y);
        let mut hidden = 0;
        for &(centre, r) in &[
            ((20, 20), 12.0),
            ((3, 3), 9.5),
            ((15, 15), 6.0),
            ((39, 0), 7.3),
        ] {
            if blocked(centre) {
                continue;
            }
            let table = LosTable::new(r);
            let obs = table.observe(centre, 40, 40, blocked);
            for (c, clear) in seen_by_rays(centre, r, on, blocked) {
                let want = if !clear {
                    UNSEEN
                } else if blocked(c) {
                    OCCUPIED
                } else {
                    FREE
                };
                assert_eq!(obs.get(c.0, c.1), Some(want), "cell {c:?} from {centre:?}");
                hidden += usize::from(!clear);
            }
        }
        assert!(hidden > 100, "the map hides enough to test: {hidden} cells");
    }
}
