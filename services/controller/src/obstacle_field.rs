//! The distance to the nearest obstacle and the direction away from it, for the repulsive
//! force of paper 002 Eq. 3 (Khatib's potential [10]).
//!
//! Built once per map with the exact Euclidean distance transform of
//! [`roam_world::distance`] (O(cells)); each query is then a constant-time lookup, not
//! a scan of the map.
//!
//! **What η is.** Obstacles are the cells the sim world treats as blocked
//! ([`roam_world::scenario::is_blocked`]: occupied or unknown), and everything off
//! the map (the grid is padded with one ring of obstacle cells before the transform, so
//! the map's edge repels like a wall). The transform gives the distance between cell
//! centres; η at a world point is that field interpolated bilinearly at the point, less
//! half a cell, so that η is the distance to the obstacle's *face*: exact for a straight
//! wall along the grid, up to (√2 − 1)/2 of a cell too long diagonally off a corner
//! (0.10 m at 0.5 m cells). A point on an obstacle cell or off the map has η = 0.
//!
//! **The direction away** is the normalised gradient of the same interpolated field, by
//! central differences half a cell wide: the unit vector from the nearest obstacle to the
//! point wherever the field is smooth. Where it is not (a ridge exactly between two
//! obstacles, the inside of a thick obstacle) the gradient can vanish and the direction
//! is zero, which is also where the repulsions from both sides cancel. Off the map the
//! direction points straight back onto it.

use roam_world::distance::squared_distance;
use roam_world::grid::Grid;
use roam_world::scenario::is_blocked;

/// The distance field of one map.
#[derive(Debug, Clone)]
pub struct ObstacleField {
    /// World position of the map's lower-left corner, metres.
    origin: [f64; 2],
    resolution: f64,
    /// The map's size in cells (without the padding).
    width: usize,
    height: usize,
    /// Distance between cell centres to the nearest obstacle centre, metres, over the
    /// padded grid of (width + 2) × (height + 2) cells, row-major.
    centre_distance_m: Vec<f32>,
    blocked: Vec<bool>,
}

impl ObstacleField {
    /// The field of an occupancy grid (ROS values; the origin's yaw is ignored, as
    /// everywhere in roam).
    pub fn new(occupancy: &Grid<i8>) -> ObstacleField {
        let (width, height) = (occupancy.width(), occupancy.height());
        let (pw, ph) = (width + 2, height + 2);
        let blocked: Vec<bool> = occupancy.cells.iter().map(|&v| is_blocked(v)).collect();
        let source = |i: usize| {
            let (x, y) = (i % pw, i / pw);
            if x == 0 || y == 0 || x == pw - 1 || y == ph - 1 {
                return true;
            }
            blocked
                .get((y - 1) * width + (x - 1))
                .copied()
                .unwrap_or(true)
        };
        let resolution = occupancy.meta.resolution;
        let centre_distance_m = squared_distance(pw, ph, source)
            .into_iter()
            .map(|d2| (f64::from(d2).sqrt() * resolution) as f32)
            .collect();
        ObstacleField {
            origin: [occupancy.meta.origin.x, occupancy.meta.origin.y],
            resolution,
            width,
            height,
            centre_distance_m,
            blocked,
        }
    }

    /// The map cell containing `p`, or `None` off the map.
    fn cell_of(&self, p: [f64; 2]) -> Option<(usize, usize)> {
        let fx = ((p[0] - self.origin[0]) / self.resolution).floor();
        let fy = ((p[1] - self.origin[1]) / self.resolution).floor();
        if !(fx >= 0.0 && fy >= 0.0 && fx < self.width as f64 && fy < self.height as f64) {
            return None;
        }
        Some((fx as usize, fy as usize))
    }

    /// The padded field interpolated bilinearly between cell centres at `p` (which must
    /// be on the map or within half a cell of it).
    fn interpolate(&self, p: [f64; 2]) -> f64 {
        let (pw, ph) = (self.width + 2, self.height + 2);
        // Continuous padded-grid coordinates in which cell centres are integers.
        let gx = ((p[0] - self.origin[0]) / self.resolution + 0.5).clamp(0.0, (pw - 1) as f64);
        let gy = ((p[1] - self.origin[1]) / self.resolution + 0.5).clamp(0.0, (ph - 1) as f64);
        let (x0, y0) = (
            (gx.floor() as usize).min(pw - 2),
            (gy.floor() as usize).min(ph - 2),
        );
        let (tx, ty) = (gx - x0 as f64, gy - y0 as f64);
        let at = |x: usize, y: usize| f64::from(self.centre_distance_m[y * pw + x]);
        let bottom = at(x0, y0) * (1.0 - tx) + at(x0 + 1, y0) * tx;
        let top = at(x0, y0 + 1) * (1.0 - tx) + at(x0 + 1, y0 + 1) * tx;
        bottom * (1.0 - ty) + top * ty
    }

    /// η: the distance from `p` to the nearest obstacle's face, metres (module doc); 0 on
    /// an obstacle cell, off the map, or for a non-finite point.
    pub fn distance_m(&self, p: [f64; 2]) -> f64 {
        let Some((x, y)) = self.cell_of(p) else {
            return 0.0;
        };
        if self
            .blocked
            .get(y * self.width + x)
            .copied()
            .unwrap_or(true)
        {
            return 0.0;
        }
        (self.interpolate(p) - 0.5 * self.resolution).max(0.0)
    }

    /// The unit vector pointing away from the nearest obstacle at `p` (module doc), or
    /// zero where it is undefined.
    pub fn away(&self, p: [f64; 2]) -> [f64; 2] {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return [0.0, 0.0];
        }
        if self.cell_of(p).is_none() {
            // Off the map: straight back onto it.
            let x_max = self.origin[0] + self.width as f64 * self.resolution;
            let y_max = self.origin[1] + self.height as f64 * self.resolution;
            let inside = [
                p[0].clamp(self.origin[0], x_max),
                p[1].clamp(self.origin[1], y_max),
            ];
            return unit([inside[0] - p[0], inside[1] - p[1]]);
        }
        let h = 0.5 * self.resolution;
        let gx = self.interpolate([p[0] + h, p[1]]) - self.interpolate([p[0] - h, p[1]]);
        let gy = self.interpolate([p[0], p[1] + h]) - self.interpolate([p[0], p[1] - h]);
        unit([gx, gy])
    }

    /// Metres per cell.
    pub fn resolution_m(&self) -> f64 {
        self.resolution
    }
}

/// `v / |v|`, or zero for a (numerically) zero or non-finite vector.
pub(crate) fn unit(v: [f64; 2]) -> [f64; 2] {
    let n = v[0].hypot(v[1]);
    if n.is_finite() && n > 1e-12 {
        [v[0] / n, v[1] / n]
    } else {
        [0.0, 0.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::{GridMeta, Origin};
    use roam_world::grid::occupancy::{FREE, OCCUPIED};

    /// A `w × h` grid of 0.5 m cells with its origin at (0, 0), cells set by `occupied`.
    fn grid(w: u32, h: u32, occupied: impl Fn(usize, usize) -> bool) -> Grid<i8> {
        let meta = GridMeta {
            width: w,
            height: h,
            resolution: 0.5,
            origin: Origin::default(),
        };
        let mut g = Grid::filled(meta, FREE);
        for y in 0..h as usize {
            for x in 0..w as usize {
                if occupied(x, y) {
                    g.cells[y * w as usize + x] = OCCUPIED;
                }
            }
        }
        g
    }

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol, "{a} != {b} (±{tol})");
    }

    #[test]
    fn a_single_wall_is_measured_to_its_face() {
        // 40 × 40 cells (20 m); a wall in column 10: x from 5.0 to 5.5 m.
        let f = ObstacleField::new(&grid(40, 40, |x, _| x == 10));
        // From x = 7.0 the face at 5.5 is 1.5 m away; the map's edges are further.
        close(f.distance_m([7.0, 10.0]), 1.5, 1e-6);
        close(f.distance_m([7.3, 10.2]), 1.8, 1e-6);
        let a = f.away([7.3, 10.2]);
        close(a[0], 1.0, 1e-9);
        close(a[1], 0.0, 1e-9);
        // West of the wall the direction flips.
        close(f.distance_m([3.0, 10.0]), 2.0, 1e-6);
        let a = f.away([3.0, 10.0]);
        close(a[0], -1.0, 1e-9);
        // On the wall itself: at the obstacle.
        assert_eq!(f.distance_m([5.2, 10.0]), 0.0);
    }

    #[test]
    fn a_corner_pushes_diagonally() {
        // One occupied cell, (10, 10): the square [5.0, 5.5]².
        let f = ObstacleField::new(&grid(40, 40, |x, y| x == 10 && y == 10));
        // Cell centre (14, 14) = (7.25, 7.25): 2√2 m between centres, minus half a cell;
        // the true distance to the square's corner is 1.75√2 = 2.475 m.
        let eta = f.distance_m([7.25, 7.25]);
        close(eta, 2.0 * 2f64.sqrt() - 0.25, 1e-5);
        close(
            eta,
            1.75 * 2f64.sqrt(),
            0.5 * (2f64.sqrt() - 1.0) / 2.0 + 1e-6,
        );
        let a = f.away([7.25, 7.25]);
        close(a[0], std::f64::consts::FRAC_1_SQRT_2, 0.02);
        close(a[1], std::f64::consts::FRAC_1_SQRT_2, 0.02);
        // Straight south of the cell, the push is straight south.
        let a = f.away([5.25, 3.0]);
        close(a[0], 0.0, 1e-9);
        close(a[1], -1.0, 1e-9);
    }

    #[test]
    fn far_points_are_beyond_the_influence_range_and_the_edge_repels() {
        let f = ObstacleField::new(&grid(40, 40, |x, _| x == 10));
        // 6.5 m from the wall's face, 6 m from the map's east edge (x = 20).
        let eta = f.distance_m([12.0, 10.0]);
        close(eta, 6.5, 1e-6);
        assert!(eta > 3.0);
        // Near the map's edge (off the map is an obstacle): 0.5 m from x = 20.
        close(f.distance_m([19.5, 10.0]), 0.5, 1e-6);
        close(f.away([19.5, 10.0])[0], -1.0, 1e-9);
        // Off the map: at an obstacle, pushed back on.
        assert_eq!(f.distance_m([21.0, 10.0]), 0.0);
        assert_eq!(f.away([21.0, 10.0]), [-1.0, 0.0]);
        assert_eq!(f.distance_m([f64::NAN, 1.0]), 0.0);
        assert_eq!(f.away([f64::NAN, 1.0]), [0.0, 0.0]);
    }

    #[test]
    fn unknown_cells_are_obstacles_like_in_the_sim() {
        let mut g = grid(20, 20, |_, _| false);
        g.cells[5 * 20 + 5] = -1;
        let f = ObstacleField::new(&g);
        assert_eq!(f.distance_m([2.75, 2.75]), 0.0);
        close(f.distance_m([2.75, 4.25]), 1.25, 1e-6);
    }
}
